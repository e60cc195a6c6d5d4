#!/usr/bin/env bash
# Every GPU goal in one go, written as one Markdown report naming the device and driver.
#
#   bash tools/gpu-report.sh [--small] [--device NAME] [--out FILE] [--no-build]
#
# Runs, in this order: `bench paper --draw soft` (the paper's counts: 100 characters x 100K
# strands at 1920x1080 among them), the people crowd of 1000 at 1920x1080, `bench animate`
# with 1000 characters, and `bench raster`. --small runs each at a size lavapipe finishes in
# minutes (a smoke run of the script itself, not figures to quote). --no-build uses the binaries
# in target/release as they are (a device machine that cannot build: build here, carry them).
# The report goes to FILE (default gpu-report.md): each step's command, its wall time and its
# output, so every figure in it names the command that made it.
set -euo pipefail
cd "$(dirname "$0")/.."

small=0
device=""
out="gpu-report.md"
build=1
while [ $# -gt 0 ]; do
    case "$1" in
        --small) small=1 ;;
        --device) device="$2"; shift ;;
        --out) out="$2"; shift ;;
        --no-build) build=0 ;;
        -h|--help) sed -n '2,12p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
        *) echo "gpu-report.sh: unknown argument $1 (see --help)" >&2; exit 2 ;;
    esac
    shift
done

if [ "$build" = 1 ]; then
    cargo build --release --bin bench --bin crowd
fi
bin=target/release
for b in bench crowd; do
    [ -x "$bin/$b" ] || { echo "gpu-report.sh: $bin/$b is missing (build first, or drop --no-build)" >&2; exit 1; }
done
dev=()
[ -n "$device" ] && dev=(--device "$device")

if [ "$small" = 1 ]; then
    paper=(paper --scale small --scenario models --draw soft)
    people=(--count 100 --size 640x360)
    animate=(animate --counts 10 --frames 4 --size 320x180)
    raster=(raster --size 320x180 --runs 1 --crowd 10 --strands 10000 --scenes head)
else
    paper=(paper --scale full --draw soft)
    people=(--count 1000 --size 1920x1080)
    animate=(animate --counts 1000)
    raster=(raster)
fi

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
report="$tmp/report.md"

# The device line the renderer prints (name and driver), from a one-frame crowd run.
"$bin/crowd" --headless --count 1 --frames 1 --size 64x64 --out "$tmp/probe" "${dev[@]}" >"$tmp/probe.txt"
device_line=$(grep -m1 '^device:' "$tmp/probe.txt" | sed 's/;.*//')
{
    echo "# GPU report"
    echo
    echo "- $device_line"
    echo "- commit $(git rev-parse --short HEAD 2>/dev/null || echo unknown), $(date -u +%Y-%m-%dT%H:%MZ), scale $([ "$small" = 1 ] && echo small || echo full)"
    if command -v nvidia-smi >/dev/null 2>&1; then
        echo "- nvidia-smi: $(nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader | head -1)"
    fi
    echo
} >"$report"

# step TITLE CMD...: run CMD, append its command line, wall time and output to the report.
step() {
    local title="$1"; shift
    echo "gpu-report: $title: $*" >&2
    local start end
    start=$(date +%s)
    if "$@" >"$tmp/step.txt" 2>&1; then status=ok; else status="failed (exit $?)"; fi
    end=$(date +%s)
    {
        echo "## $title"
        echo
        echo "\`$*\` — $status, $((end - start)) s wall"
        echo
        echo '```text'
        cat "$tmp/step.txt"
        echo '```'
        echo
    } >>"$report"
    [ "$status" = ok ]
}

failed=0
step "bench paper" "$bin/bench" "${paper[@]}" "${dev[@]}" || failed=1
step "people crowd" "$bin/crowd" --headless --frames 4 --orbit off "${people[@]}" \
    --out "$tmp/people" "${dev[@]}" || failed=1
if [ -f "$tmp/people/stats.csv" ]; then
    {
        echo "people crowd per frame (stats.csv; frame 0 compiles shaders):"
        echo
        echo '```text'
        cut -d, -f1-6 "$tmp/people/stats.csv"
        echo '```'
        echo
    } >>"$report"
fi
step "bench animate" "$bin/bench" "${animate[@]}" "${dev[@]}" || failed=1
step "bench raster" "$bin/bench" "${raster[@]}" "${dev[@]}" || failed=1

# Written whole or not at all.
cp "$report" "$out.tmp.$$" && mv "$out.tmp.$$" "$out"
echo "gpu-report: wrote $out" >&2
exit "$failed"
