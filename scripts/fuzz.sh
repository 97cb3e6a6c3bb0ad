#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Fuzzing with libFuzzer (tests/fuzz/, docs/reliability.md). Builds build-fuzz (clang-14,
# -DSSAO_FUZZ=ON: ASan + UBSan + coverage), then for every target
#   1. replays the committed regression inputs, tests/fuzz/regressions/<target>/*, as plain
#      inputs (every crash found so far, fixed: each must run clean); files named *.exr with
#      SSAO_FUZZ_RAW=1, which makes fuzz_exr read them as they are instead of as a description
#      of a file (see fuzz_exr.cpp); for fuzz_exr also the small EXR files make_exr_seeds writes;
#   2. fuzzes for SECONDS (default 15) from its seed corpus, the regression inputs and the corpus
#      earlier runs left in build-fuzz/corpus/<target>, and prints its executions (fuzz_exr:
#      from its own corpus only, its inputs describe files rather than being them).
# A crash, a sanitizer report, a leak, an input slower than 10 s, one allocation over 512 MB or
# 2 GB in use fails the run (exit 1); the input is left in build-fuzz/artifacts/ and named in
# the output.
# Usage: scripts/fuzz.sh [SECONDS [TARGET...]]   (SSAO_FUZZ_BUILD_DIR overrides build-fuzz)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${SSAO_FUZZ_BUILD_DIR:-$root/build-fuzz}
seconds=${1:-15}
shift || true
targets=("$@")
[[ ${#targets[@]} -gt 0 ]] || targets=(fuzz_api fuzz_exr fuzz_camera_json fuzz_pov_scene)

echo "fuzz: building $build"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang-14 -DCMAKE_CXX_COMPILER=clang++-14 -DSSAO_FUZZ=ON \
  -DSSAO_BUILD_TESTS=OFF -DSSAO_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" --target fuzz_targets -- -j"$(nproc)"

# Seed corpora, made fresh: small EXR files written by the project's own writer (and, when
# oiiotool is there, uncompressed copies), replayed as files; the sample camera file, the
# POV-Ray test scenes and the bridge's includes.
seeds="$build/seeds"
rm -rf "$seeds"
mkdir -p "$seeds"/{fuzz_api,fuzz_exr,fuzz_camera_json,fuzz_pov_scene}
"$build/bin/make_exr_seeds" "$seeds/fuzz_exr"
if command -v oiiotool >/dev/null; then
  for exr in "$seeds"/fuzz_exr/*.exr; do
    oiiotool "$exr" --compression none -o "${exr%.exr}_uncompressed.exr"
  done
fi
cp "$root/tests/data/sample.camera.json" "$seeds/fuzz_camera_json/"
cp "$root"/tests/povray/scenes/*.pov "$root"/povray_bridge/pov/*.inc "$seeds/fuzz_pov_scene/"

# The targets' scratch files (fuzz_common.h) stay inside the build folder.
export TMPDIR="$build/tmp"
mkdir -p "$TMPDIR" "$build/artifacts"
status=0
summary=()
for target in "${targets[@]}"; do
  binary="$build/bin/$target"
  regressions="$root/tests/fuzz/regressions/$target"
  # No input of these targets needs 512 MB in one allocation (their images are tiny): one that
  # asks for it is a finding (an allocation sized by a damaged header).
  options=(-timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=512
    -artifact_prefix="$build/artifacts/$target-")
  [[ $target == fuzz_camera_json ]] && options+=(-dict="$root/tests/fuzz/camera_json.dict")

  mapfile -t inputs < <(find "$regressions" -type f ! -name '*.exr' 2>/dev/null | sort)
  mapfile -t files < <(find "$regressions" -type f -name '*.exr' 2>/dev/null | sort)
  [[ $target == fuzz_exr ]] && files+=("$seeds"/fuzz_exr/*.exr)
  if [[ $((${#inputs[@]} + ${#files[@]})) -gt 0 ]]; then
    echo "== $target: replaying $((${#inputs[@]} + ${#files[@]})) regression inputs"
    replay_log="$build/$target.replay.log"
    : >"$replay_log"
    if ! { [[ ${#inputs[@]} -eq 0 ]] || "$binary" "${options[@]}" "${inputs[@]}"; } \
      >>"$replay_log" 2>&1 ||
      ! { [[ ${#files[@]} -eq 0 ]] || SSAO_FUZZ_RAW=1 "$binary" "${options[@]}" "${files[@]}"; } \
        >>"$replay_log" 2>&1; then
      tail -n 40 "$replay_log"
      echo "fuzz: $target FAILED on a regression input (log: $replay_log)"
      status=1
      summary+=("$target: a regression input fails")
      continue
    fi
  fi

  echo "== $target: fuzzing for $seconds s"
  corpus="$build/corpus/$target"  # first: where libFuzzer adds what it finds
  mkdir -p "$corpus"
  corpora=("$corpus")
  if [[ $target != fuzz_exr ]]; then
    corpora+=("$seeds/$target")
    [[ -d $regressions ]] && corpora+=("$regressions")
  fi
  log="$build/$target.fuzz.log"
  if "$binary" "${options[@]}" -max_total_time="$seconds" -print_final_stats=1 "${corpora[@]}" \
    >"$log" 2>&1; then
    result=ok
  else
    result=FAILED
    status=1
    tail -n 60 "$log"
    grep -E "Test unit written to" "$log" || true
  fi
  executions=$(grep -oE 'stat::number_of_executed_units: *[0-9]+' "$log" | grep -oE '[0-9]+$' ||
    echo "?")
  per_second=$(grep -oE 'stat::average_exec_per_sec: *[0-9]+' "$log" | grep -oE '[0-9]+$' ||
    echo "?")
  new_units=$(grep -oE 'stat::new_units_added: *[0-9]+' "$log" | grep -oE '[0-9]+$' || echo "?")
  line="$target: $result, $executions executions in $seconds s ($per_second/s, $new_units new inputs)"
  echo "fuzz: $line"
  summary+=("$line")
done
rm -rf "$TMPDIR"

echo "== fuzz summary"
printf '  %s\n' "${summary[@]}"
exit $status
