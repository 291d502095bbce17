// The opening of a kernel over an image: its workgroups round the image up to whole tiles, so
// the invocations past its right or bottom edge return before touching a pixel. WGSL cannot
// return from the caller inside a function, so each entry point writes
// `if outside_image(id, width, height) { return; }`.

fn outside_image(id: vec3u, width: u32, height: u32) -> bool {
    return id.x >= width || id.y >= height;
}
