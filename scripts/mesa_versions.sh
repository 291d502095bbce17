#!/usr/bin/env bash
# Lab script: the system's lavapipe against bookworm-backports' Mesa 25, one method at a time,
# without installing the newer Mesa (it is unpacked into DIR and chosen per run through
# VK_ICD_FILENAMES and LD_LIBRARY_PATH). Prints user CPU seconds per run (shader compilation
# dominates at this size). Usage: scripts/mesa_versions.sh FLICKER [DIR]  (Debian 12, root for
# apt-get's lists). docs/lab/suites-and-tests.md has the results and how to read them.
set -euo pipefail
flicker="$(realpath "$1")"
dir="$(realpath -m "${2:-/tmp/mesa25}")"
mkdir -p "$dir/state/lists/partial" "$dir/cache/archives/partial" && cd "$dir"
echo "deb http://deb.debian.org/debian bookworm-backports main" > bpo.list
apt_opts=(-o Dir::Etc::SourceList="$dir/bpo.list" -o Dir::Etc::SourceParts=/dev/null
          -o Dir::State="$dir/state" -o Dir::Cache="$dir/cache")
apt-get "${apt_opts[@]}" update -qq
apt-get "${apt_opts[@]}" download mesa-vulkan-drivers/bookworm-backports libdrm2/bookworm-backports libdrm-amdgpu1/bookworm-backports
for deb in ./*.deb; do dpkg -x "$deb" root; done
lib="$dir/root/usr/lib/x86_64-linux-gnu"
python3 -c "import json,sys; j=json.load(open('root/usr/share/vulkan/icd.d/lvp_icd.json')); j['ICD']['library_path']=sys.argv[1]; json.dump(j,open('lvp.json','w'))" "$lib/libvulkan_lvp.so"
methods=('PathTracing(spp: 1)' 'Taa()' 'SampleCache(retrace: Adaptive)' 'HashCache(taa: false)'
  'Nirc(spp: 1, predictor: Blend, cache: (encoding: (levels: 8, features_per_level: 2, log2_table_size: 12, base_resolution: 4, growth_factor: 1.5), network: (width: 32, hidden_layers: 1), reliability: (resolution: 16, log2_cells: 12, warmup: 4), max_batch: 512), paths: (termination_vertex: 1, train_records: 512))')
for i in "${!methods[@]}"; do
  cat > "one_$i.ron" <<RON
Scenario(scene: Builtin("cornell_box"), resolution: (32, 18), frames: 2, seed: 1, max_depth: 3,
  methods: [${methods[$i]}], reference: (spp: 32, frames: Every(1)))
RON
  for mesa in system backports; do
    rm -rf "run_$mesa" "cache_$mesa"
    if [ $mesa = backports ]; then env=(VK_ICD_FILENAMES="$dir/lvp.json" LD_LIBRARY_PATH="$lib"); else env=(); fi
    t=$( { env "${env[@]}" /usr/bin/time -f "%U" "$flicker" run "one_$i.ron" --out "run_$mesa" --cache-dir "cache_$mesa" --quiet >/dev/null 2>"err_$mesa"; } 2>&1; tail -1 "err_$mesa")
    driver=$(python3 -c "import json; print(json.load(open('run_$mesa/manifest.json'))['adapter']['driver_info'])")
    echo "${methods[$i]%%(*} | $driver | user ${t} s"
  done
done
