#!/usr/bin/env bash
# Whether this checkout computes what commit BASE computed, bit for bit: both
# are built without compiler-placed fused multiply-adds
# (-DOUTBURST_NO_FP_CONTRACTION=ON, whose placement moves with inlining), each
# scene is run by both on one thread, and scripts/same-results.py compares the
# two run folders (every snapshot dataset, every CSV row but wall-clock
# columns, the last checkpoint). For a refactor that should change no
# arithmetic; a change that moves results on purpose shows here, and the
# commits either side of it should each compare equal.
#
# Usage: scripts/compare-builds.sh [--other COMMIT] BASE [SCENE...]
#   --other: compare commit COMMIT with BASE instead of this checkout (to find
#   which commit of a range moved a result).
#   SCENE: a scene file, read from this checkout by both builds (default:
#   every plane scene shipped, the outburst to its end, 1 s). Work folder:
#   $COMPARE_DIR (default $TMPDIR/outburst-compare, TMPDIR by default /tmp);
#   builds are kept there and rebuilt incrementally.
# Exit 0 when every scene's results are equal, 1 when one differs.
set -euo pipefail
# Scene paths as given, from the caller's folder.
args=()
for a in "$@"; do
  case "$a" in
    *.toml) [ -f "$a" ] || { echo "$a: no such scene file" >&2; exit 2; }
            args+=("$(realpath "$a")") ;;
    *) args+=("$a") ;;
  esac
done
set -- "${args[@]+"${args[@]}"}"
cd "$(dirname "$0")/.."
commit() { git rev-parse --verify --quiet "$1^{commit}" || { echo "$1: not a commit" >&2; exit 2; }; }
other=
if [ "${1:-}" = --other ]; then
  [ $# -ge 2 ] || { echo "--other: expected a commit" >&2; exit 2; }
  other=$(commit "$2")
  shift 2
fi
[ $# -ge 1 ] || { sed -n '2,18p' "$0"; exit 2; }
base=$(commit "$1")
shift
scenes=("$@")
[ ${#scenes[@]} -gt 0 ] || scenes=(cases/bar/bar.toml cases/drainage/drainage.toml
  cases/elastic_block/elastic_block.toml cases/granular_collapse/granular_collapse.toml
  cases/gas_face/gas_face.toml cases/terzaghi/terzaghi.toml cases/mandel/mandel.toml
  cases/outburst/outburst.toml)
work=${COMPARE_DIR:-${TMPDIR:-/tmp}/outburst-compare}
mkdir -p "$work"
checkout() {  # checkout FOLDER COMMIT: a worktree of this repository at COMMIT
  if [ ! -d "$1" ]; then
    git worktree add --detach "$1" "$2" > /dev/null 2>&1
  else
    git -C "$1" checkout --quiet --detach "$2"
  fi
}
checkout "$work/base-src" "$base"

build() {  # build SOURCE_DIR BUILD_DIR
  cmake -S "$1" -B "$2" -DCMAKE_BUILD_TYPE=Release -DOUTBURST_NATIVE=ON -DOUTBURST_NO_FP_CONTRACTION=ON \
    -DOUTBURST_BUILD_TESTS=OFF -DOUTBURST_BUILD_BENCHMARKS=OFF > "$2.configure.log"
  cmake --build "$2" --target mpm-solid seepage-fe outburst -j "$(nproc)" > "$2.build.log" ||
    { echo "building $1 failed: $2.build.log" >&2; exit 2; }
}
echo "building $(git -C "$work/base-src" log -1 --format='%h %s' | cut -c1-72) ..."
build "$work/base-src" "$work/base-build"
# Each source folder keeps its own build folder (CMake ties a build to its source).
if [ -n "$other" ]; then
  checkout "$work/other-src" "$other"
  echo "building $(git -C "$work/other-src" log -1 --format='%h %s' | cut -c1-72) ..."
  head_build=$work/other-build
  build "$work/other-src" "$head_build"
else
  echo "building this checkout ($(git describe --always --dirty)) ..."
  head_build=$work/head-build
  build "$PWD" "$head_build"
fi

# The program a scene names: [scene] solvers.
program() {
  local solvers
  solvers=$(grep -m1 '^solvers' "$1")
  case "$solvers" in
    *seepage*mpm* | *mpm*seepage*) echo coupler/outburst ;;
    *mpm*) echo mpm_solid/mpm-solid ;;
    *) echo seepage_fe/seepage-fe ;;
  esac
}

differ=0
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .toml)
  p=$(program "$scene")
  for side in base head; do
    mkdir -p "$work/runs/$side"
    build_dir=$work/base-build
    [ $side = head ] && build_dir=$head_build
    OMP_NUM_THREADS=1 "$build_dir/$p" "$scene" -q -j 1 --overwrite -o "$work/runs/$side/$name" \
      > "$work/runs-$side-$name.log" 2>&1 || { echo "$name: $side run failed: $work/runs-$side-$name.log" >&2; exit 2; }
  done
  /usr/bin/python3 scripts/same-results.py "$work/runs/base/$name" "$work/runs/head/$name" || differ=1
done
exit $differ
