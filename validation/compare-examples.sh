#!/usr/bin/env bash
# Run every bundled example with two segfem binaries and compare their history.csv byte for
# byte. Used to prove a refactoring changes no result (bit-identical histories).
#
# Usage: validation/compare-examples.sh BIN_A BIN_B [EXAMPLE...]
# With no EXAMPLE, every example `BIN_A example` lists. Exit status 0 when every history is
# identical, 1 when any differs or a run fails, 2 on bad usage.
set -u

if [ $# -lt 2 ]; then
    echo "usage: $0 BIN_A BIN_B [EXAMPLE...]" >&2
    exit 2
fi
bin_a=$(realpath "$1")
bin_b=$(realpath "$2")
shift 2
for bin in "$bin_a" "$bin_b"; do
    if [ ! -x "$bin" ]; then
        echo "error: $bin is not an executable" >&2
        exit 2
    fi
done

if [ $# -gt 0 ]; then
    examples=("$@")
else
    # `segfem example` prints one example a line: its name, then a description.
    mapfile -t examples < <("$bin_a" example | awk '{print $1}')
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

status=0
for name in "${examples[@]}"; do
    for side in a b; do
        if [ "$side" = a ]; then bin=$bin_a; else bin=$bin_b; fi
        dir="$work/$side"
        mkdir -p "$dir"
        # Both sides run the model file BIN_A writes, so only the solver differs.
        if [ "$side" = a ]; then
            "$bin" example "$name" -o "$work/$name.toml" || {
                echo "$name: FAILED to write the example"
                status=1
                continue 2
            }
        fi
        # A run may stop with a non-zero status (e.g. a beam loaded to failure); the history
        # written up to then is what is compared, so the status is recorded, not fatal.
        "$bin" run -q "$work/$name.toml" -o "$dir/$name" >"$dir/$name.log" 2>&1
        echo $? >"$dir/$name.status"
    done
    sa=$(cat "$work/a/$name.status")
    sb=$(cat "$work/b/$name.status")
    ha="$work/a/$name/history.csv"
    hb="$work/b/$name/history.csv"
    if [ ! -f "$ha" ] || [ ! -f "$hb" ]; then
        echo "$name: NO HISTORY (exit status a=$sa b=$sb)"
        status=1
    elif [ "$sa" != "$sb" ]; then
        echo "$name: different exit status (a=$sa b=$sb)"
        status=1
    elif cmp -s "$ha" "$hb"; then
        echo "$name: identical ($(wc -l <"$ha") lines, exit status $sa)"
    else
        echo "$name: DIFFERENT"
        diff "$ha" "$hb" | head -5
        status=1
    fi
done
exit $status
