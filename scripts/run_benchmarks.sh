#!/usr/bin/env bash
# Builds the release preset, runs the Google Benchmark programs and writes docs/benchmarks.md.
#
#   bash scripts/run_benchmarks.sh [results folder (default results/bench)]
#
# Each program writes its JSON report to <results>/<program>.json; machine.txt records the
# processor, the core count and the load average before and after the runs. The timings are only
# as quiet as the machine: run it when nothing else is compiling or running.
set -euo pipefail
cd "$(dirname "$0")/.."

results="${1:-results/bench}"
command="bash scripts/run_benchmarks.sh"
[ $# -ge 1 ] && command="$command $1"

cmake --preset release
cmake --build --preset release

mkdir -p "$results"
machine="$results/machine.txt"
{
  echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "command: $command"
  echo "commit: $(git rev-parse --short HEAD 2>/dev/null || echo unknown)$(git diff --quiet HEAD 2>/dev/null || echo ' (with uncommitted changes)')"
  echo "nproc: $(nproc)"
  echo "cpu_model: $(grep -m1 '^model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')"
  echo "compiler: $(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' build/release/CMakeCache.txt) $(c++ -dumpfullversion 2>/dev/null || true)"
  echo "native: $(sed -n 's/^BENDLAB_NATIVE:BOOL=//p' build/release/CMakeCache.txt)"
  echo "load_start: $(cut -d' ' -f1-3 /proc/loadavg)"
} > "$machine"

for program in bench_geometry bench_bending bench_bim; do
  echo "run_benchmarks: $program -> $results/$program.json"
  "./build/release/$program" --benchmark_format=json > "$results/$program.json"
done
echo "load_end: $(cut -d' ' -f1-3 /proc/loadavg)" >> "$machine"

/usr/bin/python3 scripts/make_benchmarks_doc.py --results "$results" --out docs/benchmarks.md
echo "run_benchmarks: wrote docs/benchmarks.md"
