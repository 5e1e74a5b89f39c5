#!/usr/bin/env bash
# Fuzz every reader (issue #12): seeds each corpus from ../shared/data and data/bad (copied
# into fuzz/corpus/, which git ignores: the shared data is never committed), then runs each
# target for SECONDS under the resource policy's limits. Crashes land in fuzz/artifacts/<target>/;
# copy each into fuzz/regressions/<target>/ once fixed, and CI replays it.
#
#   fuzz/run.sh SECONDS [TARGET...]      (from the repository root; default: all targets)
#   RUNS=1000000 fuzz/run.sh 3600 hdr    (stop each target after RUNS executions instead)
#
# Besides the shared data, fuzz/seeds/<target>/ holds small valid files of our own formats
# (.cpca, .btfpca, .npy, .pc2, .mdd, a morph-target .gltf, a BTF image) that no real data set provides.
#
# Needs `cargo install cargo-fuzz`. Runs on the stable toolchain through RUSTC_BOOTSTRAP=1.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:?usage: fuzz/run.sh SECONDS [TARGET...]}
shift
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(ply obj obj_frames gltf glb npy pc2 mdd hdr exr cpca btfpca btf_image scene_toml)
fi
shared=../shared/data
seed() { # seed TARGET FILES...
  local dir=fuzz/corpus/$1; shift
  mkdir -p "$dir"
  for f in "$@"; do
    # Only small seeds: libFuzzer's default -max_len is 4096 for an empty corpus, and large
    # files slow every execution. Larger real files are cut to their first 64 KB.
    [ -f "$f" ] && head -c 65536 "$f" > "$dir/seed-$(basename "$f" | tr ' ' _)"
  done
  cp fuzz/seeds/"${dir##*/}"/* "$dir"/ 2>/dev/null || true
  cp fuzz/regressions/"${dir##*/}"/* "$dir"/ 2>/dev/null || true
}
seed ply "$shared"/meshes/bun_zipper_res4.ply data/bad/*.ply
seed obj "$shared"/meshes/teapot.obj data/bad/*.obj
seed obj_frames data/bad/mismatched_frames/1.obj
seed gltf
seed glb "$shared"/anim/gltf/Fox.glb "$shared"/anim/gltf/CesiumMan.glb
seed npy
seed pc2
seed mdd
seed hdr "$shared"/env/kiara_1_dawn_1k.hdr
seed exr
seed cpca
seed btfpca
seed btf_image
seed scene_toml crates/cloth-vis/src/demo.toml
export RUSTC_BOOTSTRAP=1
cargo fuzz build --release
for t in "${targets[@]}"; do
  echo "== $t (${seconds}s)"
  cargo fuzz run --release "$t" "fuzz/corpus/$t" -- \
    -max_total_time="$seconds" ${RUNS:+-runs=$RUNS} -rss_limit_mb=1024 -malloc_limit_mb=512 -timeout=10 \
    -print_final_stats=1 2>&1 | grep -E "^(stat::|Done|==|SUMMARY|INFO: -max_total_time|#[0-9]+ *DONE)|ERROR|crash-|leak-|oom-|timeout-" || true
  echo "corpus: $(ls "fuzz/corpus/$t" | wc -l) inputs"
done
