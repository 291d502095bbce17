// What the queries pass keeps per query for the resolve (cache_paths.wgsl).
// weight.xyz: throughput * f cos / pdf of the query direction; weight.w: 1 = a query exists.
// prefix.xyz: radiance gathered before the cache term. origin.xyz: offset ray origin of the
// query ray; origin.w: its depth (as in path_radiance), stored as a float.

struct QueryMeta {
    weight: vec4f,
    prefix: vec4f,
    origin: vec4f,
}
