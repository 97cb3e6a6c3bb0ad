#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Submits a shot to Slurm as a job array: the frames of --frames cut into chunks, one chunk per
# task (scripts/farm/ssao_array.sbatch). See docs/farm.md.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)

usage() {
  cat <<'USAGE'
Usage: scripts/farm/submit_ssao.sh [options] -- SSAO_ARGUMENTS...

Submits build/bin/ssao over a sequence as a Slurm job array, one chunk of frames per task.
SSAO_ARGUMENTS are those of a serial run and must include --frames, e.g.
  scripts/farm/submit_ssao.sh --chunk-size 10 -- 'shot/render.####.exr' \
    --camera 'shot/render.####.camera.json' --frames 1001-1100 --radius 0.5 \
    -o 'shot/ao.####.exr'
Every frame is bit for bit what the serial run writes, whatever the chunks or machines.

Options:
  --chunk-size N      frames per task (default 10)
  --cpus-per-task C   cores per task, passed to ssao as --threads (default 2)
  --max-running M     at most M tasks at once (the array's %M)
  --log-dir DIR       where the tasks' logs go (default: the current folder),
                      as ssao-JOBID_TASK.log
  --sbatch ARG        one more sbatch option, e.g. --sbatch=--partition=render
                      (repeatable)
  --dry-run           print the chunks and the sbatch command, submit nothing
  -h, --help          this help

Environment: SSAO_BIN, the ssao program the tasks run (default: this checkout's
build/bin/ssao; it must be at the same path on every node).
Prints the job id on stdout (sbatch --parsable); the chunks and how to watch on stderr.
USAGE
}

fail() {
  echo "submit_ssao: error: $*" >&2
  exit 2
}

chunk_size=10 cpus=2 max_running="" log_dir="" dry_run=0
sbatch_extra=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    -h | --help) usage; exit 0 ;;
    --chunk-size) chunk_size=${2:?--chunk-size needs a value}; shift 2 ;;
    --chunk-size=*) chunk_size=${1#*=}; shift ;;
    --cpus-per-task) cpus=${2:?--cpus-per-task needs a value}; shift 2 ;;
    --cpus-per-task=*) cpus=${1#*=}; shift ;;
    --max-running) max_running=${2:?--max-running needs a value}; shift 2 ;;
    --max-running=*) max_running=${1#*=}; shift ;;
    --log-dir) log_dir=${2:?--log-dir needs a value}; shift 2 ;;
    --log-dir=*) log_dir=${1#*=}; shift ;;
    --sbatch) sbatch_extra+=("${2:?--sbatch needs a value}"); shift 2 ;;
    --sbatch=*) sbatch_extra+=("${1#*=}"); shift ;;
    --dry-run) dry_run=1; shift ;;
    --) shift; break ;;
    *) fail "unknown option '$1' (the ssao arguments go after --; see --help)" ;;
  esac
done
[[ $# -gt 0 ]] || fail "no ssao arguments (after --); see --help"
[[ "$chunk_size" =~ ^[1-9][0-9]*$ ]] || fail "--chunk-size must be a positive number, got '$chunk_size'"
[[ "$cpus" =~ ^[1-9][0-9]*$ ]] || fail "--cpus-per-task must be a positive number, got '$cpus'"
[[ -z "$max_running" || "$max_running" =~ ^[1-9][0-9]*$ ]] ||
  fail "--max-running must be a positive number, got '$max_running'"

ssao_bin=${SSAO_BIN:-$root/build/bin/ssao}
[[ -x "$ssao_bin" ]] || fail "no ssao program at '$ssao_bin' (build it, or set SSAO_BIN)"
ssao_bin=$(cd "$(dirname "$ssao_bin")" && pwd)/$(basename "$ssao_bin")

# ssao itself checks the whole command line and cuts the frames: the tasks do the same.
chunks=$("$ssao_bin" "$@" --chunk-size "$chunk_size" --list-chunks) ||
  fail "ssao refused the arguments (above)"
[[ -n "$chunks" ]] || fail "the ssao arguments have no --frames"
count=$(printf '%s\n' "$chunks" | wc -l)
array="0-$((count - 1))${max_running:+%$max_running}"

log="ssao-%A_%a.log"
if [[ -n "$log_dir" ]]; then
  mkdir -p "$log_dir" || fail "cannot create the log folder '$log_dir'"
  log="$log_dir/$log"
fi
command=(sbatch --parsable --array="$array" --cpus-per-task="$cpus" --output="$log"
  "${sbatch_extra[@]}" "$root/scripts/farm/ssao_array.sbatch" "$@")

echo "submit_ssao: $count chunks of up to $chunk_size frames (tasks $array):" >&2
printf '%s\n' "$chunks" | head -n 20 | sed 's/^/  /' >&2
[[ $count -le 20 ]] || echo "  ..." >&2
if [[ $dry_run -eq 1 ]]; then
  printf 'SSAO_BIN=%q SSAO_CHUNK_SIZE=%q' "$ssao_bin" "$chunk_size"
  printf ' %q' "${command[@]}"
  printf '\n'
  exit 0
fi
command -v sbatch >/dev/null || fail "sbatch not found: is this a Slurm submit host?"
job=$(SSAO_BIN="$ssao_bin" SSAO_CHUNK_SIZE="$chunk_size" "${command[@]}") ||
  fail "sbatch failed (above)"
job=${job%%;*}  # --parsable prints JOBID[;CLUSTER]
echo "submit_ssao: submitted job $job; watch it with: squeue -j $job" >&2
echo "$job"
