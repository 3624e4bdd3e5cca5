#!/usr/bin/env bash
# Runs `molremesh report` and `molremesh remesh` on every file of a hostile corpus (from
# scripts/make_hostile_inputs.py) with a time limit each, and prints a tally: crashes (signals),
# hangs (time limit hit), exit statuses outside {0,1,2,3}, sanitizer findings, and failures (exit 1
# or 2) whose stderr is not exactly one "molremesh: error:" line. Exit status 0 when all those are 0.
# usage: run_hostile.sh MOLREMESH CORPUS_DIR [SECONDS_PER_RUN (10)] [EVERY_NTH_FILE (1)]
#   JOBS=n runs n files at once (default 1: a loaded machine makes the time limit unfair).
#   The per-run results go to $HOSTILE_LOG (default: a temp file, printed at the end).
set -u
if [ "${1:-}" = "--one" ]; then # worker: one file, both commands
  bin=$2 limit=$3 work=$4 file=$5
  name=$(basename "$file")
  for mode in report remesh; do
    err="$work/$name.$mode.err"
    if [ "$mode" = report ]; then
      timeout -k 2 "$limit" "$bin" report "$file" >/dev/null 2>"$err"
    else
      timeout -k 2 "$limit" "$bin" remesh --quiet "$file" "$work/$name.out.ply" >/dev/null 2>"$err"
    fi
    rc=$?
    rm -f "$work/$name.out.ply"
    class=ok
    if grep -qE 'AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer|runtime error:' "$err"; then
      class=sanitizer
    elif [ "$rc" = 124 ] || [ "$rc" = 137 ]; then
      class=hang
    elif [ "$rc" -gt 128 ]; then
      class=crash
    elif [ "$rc" -gt 3 ]; then
      class=exit_outside
    elif [ "$rc" = 1 ] || [ "$rc" = 2 ]; then
      lines=$(grep -c . "$err")
      if [ "$lines" != 1 ] || ! grep -q '^molremesh: error: ' "$err"; then class=not_one_line; fi
    elif [ "$rc" = 3 ] && grep -v '^molremesh: warning: ' "$err" | grep -q .; then
      class=not_one_line
    fi
    first=$(head -c 300 "$err" | head -n 1 | tr '\t' ' ')
    printf '%s\t%s\t%s\t%s\t%s\n' "$class" "$rc" "$mode" "$name" "$first"
    rm -f "$err"
  done
  exit 0
fi

bin=${1:?usage: run_hostile.sh MOLREMESH CORPUS_DIR [SECONDS] [EVERY_NTH]}
corpus=${2:?usage: run_hostile.sh MOLREMESH CORPUS_DIR [SECONDS] [EVERY_NTH]}
limit=${3:-10}
every=${4:-1}
jobs=${JOBS:-1}
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
work=$(mktemp -d)
log=${HOSTILE_LOG:-$work/results.tsv}
trap 'rm -rf "$work/files"' EXIT
mkdir -p "$work/files"
script=$(cd "$(dirname "$0")" && pwd)/$(basename "$0")
start=$(date +%s)
find "$corpus" -maxdepth 1 -type f | sort | awk -v n="$every" '(NR - 1) % n == 0' |
  xargs -d '\n' -P "$jobs" -n 1 bash "$script" --one "$bin" "$limit" "$work/files" >"$log" 2>/dev/null
seconds=$(($(date +%s) - start))
count() { awk -F'\t' -v c="$1" '$1 == c' "$log" | wc -l; }
files=$(cut -f4 "$log" | sort -u | wc -l)
runs=$(wc -l <"$log")
echo "hostile corpus: $files files, $runs runs (report + remesh, ${limit} s limit) in ${seconds} s with $bin"
echo "exit statuses: $(cut -f2 "$log" | sort -n | uniq -c | awk '{printf "%s:%s ", $2, $1}')"
bad=0
for c in crash hang exit_outside sanitizer not_one_line; do
  n=$(count "$c")
  echo "$c: $n"
  [ "$n" = 0 ] || bad=1
done
if [ "$bad" = 1 ]; then
  echo "-- offending runs (class, status, command, file, first stderr line):"
  awk -F'\t' '$1 != "ok"' "$log" | head -n 60
fi
[ -z "${HOSTILE_LOG:-}" ] && rm -f "$log"
exit "$bad"
