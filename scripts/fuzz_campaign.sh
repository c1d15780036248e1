#!/usr/bin/env bash
# The fuzzing campaign of docs/fuzzing.md: every `cargo fuzz` target for at least
# FUZZ_CPU_SECONDS of CPU time (default 600, ten CPU-minutes), FUZZ_JOBS targets at a time
# (default 2), each under -rss_limit_mb=2048, continuing after a crash (libFuzzer fork mode with
# one worker), then a table of runs, coverage and crashes.
#
#   bash scripts/fuzz_campaign.sh                 # all targets
#   FUZZ_CPU_SECONDS=60 bash scripts/fuzz_campaign.sh cdr urdf   # a quick look at two
#
# Needs the nightly toolchain and cargo-fuzz (`cargo install cargo-fuzz`); `.ci/run` does not
# run this (it replays fuzz/regressions/ through `cargo test --test fuzz_regressions`).
# Output: fuzz/artifacts/<target>/ (crash-*, oom-*, timeout-* inputs and a .log with each one's
# panic), fuzz/artifacts/campaign.md (the table), fuzz/corpus/<target>/ (the grown corpus).
# The targets never open a network socket (no DDS: the library is built without `ros`).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$ROOT"
CPU_SECONDS=${FUZZ_CPU_SECONDS:-600}
JOBS=${FUZZ_JOBS:-2}
ALL_TARGETS=(urdf mesh_stl mesh_obj mesh_dae cdr state_line params_yaml bag_mcap bag_sqlite check_trajectory check_state_validity srdf)
if [ $# -gt 0 ]; then TARGETS=("$@"); else TARGETS=("${ALL_TARGETS[@]}"); fi
TRIPLE=x86_64-unknown-linux-gnu
BIN_DIR=fuzz/target/$TRIPLE/release
OUT=fuzz/artifacts
mkdir -p "$OUT" fuzz/corpus

if ! cargo +nightly fuzz --version >/dev/null 2>&1; then
    echo "fuzz_campaign: cargo-fuzz is missing: cargo install cargo-fuzz (and rustup toolchain install nightly)" >&2
    exit 2
fi

# 1. Build every target once (release, debug assertions and overflow checks on). No sanitizer:
#    the Rust code is memory-safe outside its dependencies' unsafe blocks, and the C parts
#    (SQLite, zstd, lz4) are not instrumented by cargo fuzz either; ASan would halve the runs.
echo "fuzz_campaign: building the targets"
cargo +nightly fuzz build -s none

# 2. Seeds: generated from the bundled workcell by the library (examples/fuzz_seeds.rs), the
#    saved inputs of fuzz/regressions/<target>/ (passed as a second corpus directory), and the
#    small URDF, STL and COLLADA files of example-robot-data when the test venv has it.
echo "fuzz_campaign: writing the seed corpus"
cargo run --quiet --example fuzz_seeds -- "$ROOT/fuzz/corpus" >/dev/null
VENV=${TC_VENV:-$HOME/.cache/thickness_collision/venv}
if [ -d "$VENV" ]; then
    for ext in urdf:urdf stl:mesh_stl dae:mesh_dae obj:mesh_obj; do
        suffix=${ext%%:*} target=${ext##*:}
        mkdir -p "fuzz/corpus/$target"
        mapfile -t found < <(find "$VENV" -path '*example-robot-data*' -name "*.$suffix" -size -64k 2>/dev/null | sort)
        for f in "${found[@]:0:40}"; do
            cp "$f" "fuzz/corpus/$target/erd_$(echo "$f" | md5sum | cut -c1-12).$suffix"
        done
    done
fi

COMMIT=$(git rev-parse --short HEAD)
DIRTY=$(git status --porcelain --untracked-files=no | wc -l)

# 3. One target: fork mode with one worker, restarted until its CPU time reaches the budget
#    (the machine may be shared: wall time is not CPU time). CPU time is user + system of the
#    fuzzer and its workers, from /usr/bin/time.
run_target() {
    local t=$1 cpu=0 round=0 log stats
    mkdir -p "$OUT/$t" "fuzz/corpus/$t" "fuzz/regressions/$t"
    : >"$OUT/$t/contained_panics.txt"
    log="$OUT/$t/fuzz.log"
    : >"$log"
    while awk -v c="$cpu" -v b="$CPU_SECONDS" 'BEGIN { exit !(c < b) }'; do
        round=$((round + 1))
        local remaining
        remaining=$(awk -v c="$cpu" -v b="$CPU_SECONDS" 'BEGIN { r = int(b - c + 0.999); print (r < 10 ? 10 : r) }')
        mkdir -p "$OUT/$t/tmp"
        # The bag targets write their input to a file under TMPDIR: one per target, removed after.
        TMPDIR="$ROOT/$OUT/$t/tmp" FUZZ_CONTAINED_PANICS_LOG="$ROOT/$OUT/$t/contained_panics.txt" /usr/bin/time -f "cpu_seconds %U %S" -o "$OUT/$t/time.$round" \
            "$BIN_DIR/$t" "fuzz/corpus/$t" "fuzz/regressions/$t" \
            -fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1 \
            -max_total_time="$remaining" -rss_limit_mb=2048 -timeout=30 -max_len=1048576 \
            -artifact_prefix="$OUT/$t/" -print_final_stats=1 >>"$log" 2>&1 || true
        cpu=$(awk -v c="$cpu" '/^cpu_seconds/ { c += $2 + $3 } END { print c }' "$OUT/$t/time.$round")
        rm -rf "$OUT/$t/tmp"
    done
    echo "$cpu" >"$OUT/$t/cpu_seconds"
    echo "$round" >"$OUT/$t/rounds"
    echo "fuzz_campaign: $t done ($cpu CPU seconds)"
}

echo "fuzz_campaign: ${#TARGETS[@]} targets, $CPU_SECONDS CPU seconds each, $JOBS at a time (commit $COMMIT, $DIRTY files changed)"
START=$(date +%s)
running=0
for t in "${TARGETS[@]}"; do
    if [ ! -x "$BIN_DIR/$t" ]; then
        echo "fuzz_campaign: no target $t (have: ${ALL_TARGETS[*]})" >&2
        exit 2
    fi
    rm -f "$OUT/$t"/crash-* "$OUT/$t"/oom-* "$OUT/$t"/timeout-* "$OUT/$t"/slow-unit-* "$OUT/$t"/time.*
    run_target "$t" &
    running=$((running + 1))
    if [ "$running" -ge "$JOBS" ]; then
        wait -n
        running=$((running - 1))
    fi
done
wait
WALL=$(($(date +%s) - START))

# 4. Each crash input replayed once more to keep its panic message; then the table.
TABLE="$OUT/campaign.md"
{
    echo "Commit $COMMIT ($DIRTY tracked files changed in the working tree), $(date -u +%Y-%m-%d), $WALL s wall,"
    echo "\`FUZZ_CPU_SECONDS=$CPU_SECONDS FUZZ_JOBS=$JOBS bash scripts/fuzz_campaign.sh ${*:-}\`"
    echo
    echo "| target | CPU s | runs | exec/s | coverage (cov / ft) | corpus | crashes | ooms | timeouts | contained panics |"
    echo "|---|---:|---:|---:|---|---:|---:|---:|---:|---:|"
} >"$TABLE"
for t in "${TARGETS[@]}"; do
    for a in "$OUT/$t"/crash-* "$OUT/$t"/oom-* "$OUT/$t"/timeout-*; do
        [ -f "$a" ] || continue
        case "$a" in *.log) continue ;; esac
        timeout 60 "$BIN_DIR/$t" "$a" -rss_limit_mb=2048 >"$a.log" 2>&1 || true
    done
    # Fork mode's status lines: "#RUNS: cov: C ft: F corp: N exec/s: E oom/timeout/crash: a/b/c time: Ts job: J".
    last=$(grep -E '^#[0-9]+: cov:' "$OUT/$t/fuzz.log" | tail -n 1 || true)
    # Runs: the last count of each round (the count starts again when a round is restarted).
    runs=$(grep -E '^#[0-9]+: cov:' "$OUT/$t/fuzz.log" | awk -F'[#:]' '{ n = $2 + 0; if (n < p) s += p; p = n } END { print s + p }')
    cov=$(echo "$last" | sed -nE 's/.* cov: ([0-9]+) ft: ([0-9]+).*/\1 \/ \2/p')
    corp=$(find "fuzz/corpus/$t" -type f | wc -l)
    cpu=$(cat "$OUT/$t/cpu_seconds")
    eps=$(awk -v r="${runs:-0}" -v c="$cpu" 'BEGIN { printf "%.0f", (c > 0 ? r / c : 0) }')
    ncrash=$(find "$OUT/$t" -name 'crash-*' ! -name '*.log' | wc -l)
    noom=$(find "$OUT/$t" -name 'oom-*' ! -name '*.log' | wc -l)
    ntime=$(find "$OUT/$t" -name 'timeout-*' ! -name '*.log' | wc -l)
    # Distinct places ("panicked at file:line"), whatever the message's numbers.
    ncont=$(sed -E 's/^(panicked at [^ ]*:[0-9]+).*/\1/' "$OUT/$t/contained_panics.txt" | sort -u | grep -c . || true)
    printf '| %s | %.0f | %s | %s | %s | %s | %s | %s | %s | %s |\n' "$t" "$cpu" "${runs:-0}" "$eps" "${cov:-?}" "$corp" "$ncrash" "$noom" "$ntime" "$ncont" >>"$TABLE"
done
cat "$TABLE"
echo "fuzz_campaign: crash inputs and their panics in $OUT/<target>/; contained mesh-loader panics in $OUT/<target>/contained_panics.txt"
