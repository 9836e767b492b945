#!/usr/bin/env bash
# Looks for new failing cases: the workspace's property tests with fresh seeds (stable), then the
# cargo-fuzz targets in fuzz/ (nightly), each for a bounded time, and reports libFuzzer's final
# figures. Exits non-zero if any property test fails or any target crashes (or fails to build).
#
#   bash scripts/fuzz.sh                                   # both: property tests, then every
#                                                          # cargo-fuzz target, 600 s each
#   bash scripts/fuzz.sh proptest                          # the property tests only
#   bash scripts/fuzz.sh cargo-fuzz                        # the cargo-fuzz targets only
#   PROPTEST_ROUNDS=20 bash scripts/fuzz.sh proptest       # 20 fresh seeds (default 5)
#   FUZZ_SECONDS=60 bash scripts/fuzz.sh cargo-fuzz        # shorter
#   FUZZ_TARGETS=frame_decoder bash scripts/fuzz.sh        # one target
#   FUZZ_SANITIZER=none bash scripts/fuzz.sh               # no ASan (faster; the crates are
#                                                          # safe Rust, their deps are not all)
#
# Property tests: the test command (scripts/test-all.sh) and CI draw every proptest's cases from
# the one fixed seed in .cargo/config.toml ([env] PROPTEST_RNG_SEED), so they give the same result
# on every run. This script is the opt-in to fresh seeds: each round draws a new seed, runs every
# test file that holds a `proptest!` with it, and prints it. A failure is reproduced exactly by
# the same test with that seed (PROPTEST_RNG_SEED=<seed> cargo test --profile host
# --manifest-path <crate>/Cargo.toml --test <file>); promote the minimal failing input proptest
# prints to a named regression test. No .proptest-regressions file is written (.cargo/config.toml
# sets PROPTEST_DISABLE_FAILURE_PERSISTENCE).
#
# Corpora grow in fuzz/corpus/<target>/ (kept between runs), crashes land in
# fuzz/artifacts/<target>/, full logs in fuzz/artifacts/<target>.log; all git-ignored.
# Reproduce a crash:  cargo +nightly fuzz run <target> fuzz/artifacts/<target>/crash-…
# Minimize it:        cargo +nightly fuzz tmin <target> fuzz/artifacts/<target>/crash-…
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
mode="${1:-all}"
case "$mode" in
    all | proptest | cargo-fuzz) ;;
    *) echo "usage: bash scripts/fuzz.sh [proptest | cargo-fuzz]" >&2; exit 2 ;;
esac

failed=()
summary=()

# The test files that hold property tests, as cargo arguments: a crate's tests/<name>.rs is
# `--manifest-path <crate>/Cargo.toml --test <name>`. Found by their `proptest!`, so a new one
# is included without editing this script.
proptest_targets() {
    grep -rl --include='*.rs' 'proptest!' "$root" --exclude-dir=target --exclude-dir=fuzz |
        sed -n "s|^$root/\(.*\)/tests/\([^/]*\)\.rs$|\1 \2|p" | sort
}

if [ "$mode" != cargo-fuzz ]; then
    rounds="${PROPTEST_ROUNDS:-5}"
    mapfile -t targets < <(proptest_targets)
    proptest_log="$(mktemp)"
    trap 'rm -f "$proptest_log"' EXIT
    echo "== property tests: ${#targets[@]} files, $rounds fresh seeds"
    for t in "${targets[@]}"; do
        read -r crate test <<<"$t"
        cargo test --profile host --manifest-path "$root/$crate/Cargo.toml" --test "$test" --no-run -q
    done
    for round in $(seq "$rounds"); do
        seed="$(od -An -N8 -tu8 /dev/urandom | tr -d ' ')"
        echo "-- round $round: PROPTEST_RNG_SEED=$seed"
        for t in "${targets[@]}"; do
            read -r crate test <<<"$t"
            args=(--profile host --manifest-path "$root/$crate/Cargo.toml" --test "$test")
            if ! PROPTEST_RNG_SEED="$seed" cargo test "${args[@]}" -q >"$proptest_log" 2>&1; then
                failed+=("proptest $crate/tests/$test.rs seed $seed")
                echo "!! $crate/tests/$test.rs FAILED with PROPTEST_RNG_SEED=$seed"
                grep -E 'minimal failing input|panicked at|Test failed' "$proptest_log" | head -n 20 || true
                echo "   reproduce: PROPTEST_RNG_SEED=$seed cargo test ${args[*]}"
            fi
        done
    done
    summary+=("proptest: ${#targets[@]} files × $rounds seeds")
fi

if [ "$mode" = proptest ]; then
    printf '%s\n' "${summary[@]}"
    if [ "${#failed[@]}" -ne 0 ]; then
        echo "FAILED: ${failed[*]}"
        exit 1
    fi
    echo "no failures"
    exit 0
fi

cd "$root/fuzz"

FUZZ_SECONDS="${FUZZ_SECONDS:-600}"
FUZZ_TARGETS="${FUZZ_TARGETS:-frame_decoder controller_update supervisor}"
FUZZ_SANITIZER="${FUZZ_SANITIZER:-address}"

if ! cargo +nightly fuzz --version >/dev/null 2>&1; then
    echo "== installing cargo-fuzz"
    cargo +nightly install cargo-fuzz --locked
fi

# Longest input worth generating: controller_update reads 75 bytes; frame_decoder needs room
# for a few frames of up to auv_link::MAX_FRAME bytes and for oversize ones.
max_len() {
    case "$1" in
        controller_update) echo 128 ;;
        frame_decoder) echo 1024 ;;
        # A few hundred ops (frames, commands, periods); the harness stops at 512 ops.
        supervisor) echo 2048 ;;
        *) echo 4096 ;;
    esac
}

echo "== building fuzz targets (sanitizer: $FUZZ_SANITIZER)"
cargo +nightly fuzz build -s "$FUZZ_SANITIZER"

for target in $FUZZ_TARGETS; do
    corpus="corpus/$target"
    artifacts="artifacts/$target"
    log="artifacts/$target.log"
    mkdir -p "$corpus" "$artifacts"
    before="$(find "$artifacts" -type f | sort)"

    echo "== $target: ${FUZZ_SECONDS}s (log: fuzz/$log)"
    start=$(date +%s)
    set +e
    cargo +nightly fuzz run -s "$FUZZ_SANITIZER" "$target" -- \
        -max_total_time="$FUZZ_SECONDS" \
        -max_len="$(max_len "$target")" \
        -timeout=10 \
        -print_final_stats=1 \
        2>&1 | tee "$log" | grep --line-buffered -E 'INITED|pulse|DONE|ERROR|panicked|SUMMARY|Test unit written'
    status=${PIPESTATUS[0]}
    set -e
    elapsed=$(($(date +%s) - start))

    done_line="$(grep -E '^#[0-9]+[[:space:]]+DONE' "$log" | tail -n 1 || true)"
    execs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)"
    rate="$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)"
    cov="$(grep -oE 'cov: [0-9]+ ft: [0-9]+' "$log" | tail -n 1 || true)"
    files="$(find "$corpus" -type f | wc -l)"
    bytes="$(find "$corpus" -type f -printf '%s\n' | awk '{s += $1} END {print s + 0}')"
    new="$(comm -13 <(echo "$before") <(find "$artifacts" -type f | sort))"

    echo "-- $target: ${done_line:-no DONE line (crashed or stopped)}"
    echo "-- $target: executions ${execs:-?}, exec/s ${rate:-?}, ${cov:-cov: ?}," \
        "corpus $files files / $bytes bytes, ${elapsed}s, exit $status"
    summary+=("$(printf '%-18s %12s %8s %-22s %6s files %9s bytes %5ss exit %s' \
        "$target" "${execs:-?}" "${rate:-?}" "${cov:-cov: ?}" "$files" "$bytes" "$elapsed" "$status")")

    if [ "$status" -ne 0 ] || [ -n "$new" ]; then
        failed+=("$target")
        echo "!! $target FAILED (exit $status); new artifacts:"
        [ -z "$new" ] || printf '   fuzz/%s\n' $new
        for a in $new; do
            echo "   reproduce: (cd fuzz && cargo +nightly fuzz run -s $FUZZ_SANITIZER $target $a)"
            echo "   minimize:  (cd fuzz && cargo +nightly fuzz tmin -s $FUZZ_SANITIZER $target $a)"
        done
        grep -E 'panicked at|assertion|Test unit written' "$log" | head -n 20 || true
    fi
done

echo
echo "== summary (target, executions, exec/s, coverage, corpus, time, exit)"
printf '%s\n' "${summary[@]}"
if [ "${#failed[@]}" -ne 0 ]; then
    echo "FAILED: ${failed[*]}"
    exit 1
fi
echo "no crashes"
