#!/bin/sh
# Build the libFuzzer targets (tests/fuzz/build.sh) and run each one for a
# fixed time over its seed corpus tests/fuzz/corpus/<target>/.
#
# Usage: tests/fuzz/run.sh [SECONDS_PER_TARGET] [TARGET...]
#   SECONDS_PER_TARGET  default $FUZZ_TIME or 60
#   TARGET              default: every target build.sh built
# Environment: FUZZ_BUILD (build directory, default tests/fuzz/build),
#   FUZZ_ARTIFACTS (where crashing inputs go, default tests/fuzz/artifacts).
#
# The seed corpus is only read: new inputs go to a scratch copy, so a run
# leaves the tree as it was. Prints one line per target (runs, exec/s,
# coverage) and exits 1 if any target crashed, leaked, timed out or ran out
# of memory; the input is then in FUZZ_ARTIFACTS (reproduce with
# `tests/fuzz/build/<target> <file>`).
set -u
SRC=$(cd "$(dirname "$0")/../.." && pwd)
SECONDS_PER_TARGET=${1:-${FUZZ_TIME:-60}}
[ $# -gt 0 ] && shift
BUILD=${FUZZ_BUILD:-$SRC/tests/fuzz/build}
ARTIFACTS=${FUZZ_ARTIFACTS:-$SRC/tests/fuzz/artifacts}

# The build's own exit status decides (a pipeline would report sed's), and
# no target built is a failure too: a run that fuzzes nothing must not pass.
blog=$(mktemp)
if ! "$SRC/tests/fuzz/build.sh" "$BUILD" >"$blog"; then
    rm -f "$blog"
    echo "fuzz: build failed"
    exit 1
fi
built=$(sed -n 's/^built: //p' "$blog")
rm -f "$blog"
if [ -z "$built" ]; then
    echo "fuzz: no target was built"
    exit 1
fi
targets=${*:-$built}
mkdir -p "$ARTIFACTS"
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT INT TERM

# Leaks count as failures; UBSan stops at the first report with its stack.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1:symbolize=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}

failed=0
for t in $targets; do
    seeds="$SRC/tests/fuzz/corpus/$t"
    mkdir -p "$scratch/$t" "$seeds"
    log="$scratch/$t.log"
    touch "$scratch/$t.start"
    # -timeout: one input taking 10 s is a hang; -rss_limit_mb: the machine
    # is shared, an input that needs 2 GiB is a finding.
    "$BUILD/$t" -max_total_time="$SECONDS_PER_TARGET" -timeout=10 \
        -rss_limit_mb=2048 -print_final_stats=1 \
        -artifact_prefix="$ARTIFACTS/$t-" "$scratch/$t" "$seeds" >"$log" 2>&1
    rc=$?
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n1)
    speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n1)
    cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$log" | tail -n1)
    nseeds=$(find "$seeds" -type f | wc -l)
    if [ "$rc" = 0 ]; then
        echo "fuzz: $t: ${runs:-?} runs in ${SECONDS_PER_TARGET} s (${speed:-?} exec/s)," \
             "${cov:-cov: ?}, $nseeds seeds, no crash"
    else
        failed=1
        echo "fuzz: $t: FAILED (exit $rc) after ${runs:-?} runs; last lines of its log:"
        tail -n 60 "$log"
        # The input itself, so that a CI log is enough to reproduce it.
        find "$ARTIFACTS" -name "$t-*" -newer "$scratch/$t.start" | while read -r a; do
            echo "fuzz: input: $a ($(wc -c <"$a") bytes), base64:"
            head -c 4096 "$a" | base64
        done
    fi
done
exit $failed
