#!/usr/bin/env bash
# Mutation testing of segfem's physics modules with cargo-mutants (issue 42 item 4).
#
# Each module is mutated alone (`cargo mutants -f FILE`) and every mutant is run against the
# fast tests that cover that module: its unit tests in the library and one or two integration
# test binaries, never the whole suite. Builds are incremental in the repository's own
# dev target (`--in-place`, the dev profile: opt-level 1, dependencies at 3, incremental, so a
# mutant recompiles a few codegen units instead of the release crate; cargo-mutants restores
# the file after each mutant and on Ctrl-C; if it is killed hard, `git checkout -- src/`
# restores the sources). Run it in a worktree of its own, not in a checkout you edit.
# Not for CI: a whole module takes hours on a 2-core machine (src/prestress/friction.rs
# alone has 352 mutants, src/materials/concrete/ 2,813); SHARD samples a module.
#
# Usage:
#   validation/mutants.sh                       # every module below, one after the other
#   validation/mutants.sh friction interface    # some modules
#   SHARD=0/16 validation/mutants.sh friction   # one 16th of the mutants (round robin)
#   validation/mutants.sh --list                # the modules, files and tests
#
# Two tiers: every mutant against all the library's unit tests (3 s), then only the mutants
# those missed against the module's integration test binaries as well.
# Results: target/mutants/<module>/mutants.out/ (tier 1) and
# target/mutants/<module>-integration/mutants.out/ (tier 2): {caught,missed,timeout,
# unviable}.txt and outcomes.json; the last lines of each run give the counts. Record the figures, with the date,
# in docs/validation.md ("Mutation testing").
set -euo pipefail
cd "$(dirname "$0")/.."

# Module name | source files (space separated) | test binaries (--test) | nextest filter.
MODULES=(
    "mc90_time|src/materials/mc90_time.rs|time bonded_losses|test(/^materials::mc90_time::/) | binary(time) | binary(bonded_losses)"
    "chain|src/materials/chain.rs|time stages|test(/^materials::chain::/) | binary(time) | binary(stages)"
    "concrete|src/materials/concrete/*.rs|panels concrete_engine|test(/^materials::concrete::/) | binary(panels) | (binary(concrete_engine) & !test(/^rc_beam_/))"
    "steel|src/materials/steel.rs|properties|test(/^materials::steel::/) | binary(properties)"
    "friction|src/prestress/friction.rs|prestress bonded_losses|test(/^prestress::/) | binary(prestress) | binary(bonded_losses)"
    "interface|src/elements/interface.rs|joints|test(/^elements::interface::/) | binary(joints)"
    "tendon|src/elements/tendon.rs|tendons properties|test(/^elements::tendon::/) | binary(tendons) | binary(properties)"
    "thermal|src/model/thermal.rs|thermal|test(/^model::thermal::/) | binary(thermal)"
)

if [[ "${1:-}" == "--list" ]]; then
    for m in "${MODULES[@]}"; do
        IFS='|' read -r name files tests filter <<<"$m"
        echo "$name: files $files; tests --lib ${tests}; filter: $filter"
    done
    exit 0
fi

if ! cargo mutants --version >/dev/null 2>&1; then
    cargo install --locked cargo-mutants
fi

wanted=("$@")
for m in "${MODULES[@]}"; do
    IFS='|' read -r name files tests filter <<<"$m"
    if ((${#wanted[@]})) && [[ ! " ${wanted[*]} " == *" $name "* ]]; then
        continue
    fi
    common=(--in-place --profile mutants --test-tool nextest --no-shuffle --timeout 300)
    for f in $files; do
        common+=(-f "$f")
    done
    # Tier 1: every mutant against the library's unit tests (all of them: 3 s), one crate
    # build per mutant.
    args=("${common[@]}" --output "target/mutants/$name" --cargo-arg=--lib)
    if [[ -n "${SHARD:-}" ]]; then
        args+=(--shard "$SHARD" --sharding round-robin)
    fi
    mkdir -p "target/mutants/$name"
    echo "== $name ($(date -u +%F)) tier 1: cargo mutants ${args[*]}"
    # Missed mutants make cargo-mutants exit non-zero: carry on.
    cargo mutants "${args[@]}" || true
    out="target/mutants/$name/mutants.out"
    if ! grep -q '"Mutant"' "$out/outcomes.json" 2>/dev/null; then
        # The unmutated tree did not build or pass (e.g. a stale incremental cache after a
        # killed run: remove target/mutants/incremental and retry).
        echo "$name: no mutant tested; see $out/log/ and $out/debug.log" >&2
        continue
    fi
    # Tier 2: the mutants the unit tests missed, against the module's integration tests too.
    missed="$out/missed.txt"
    out2="target/mutants/$name-integration/mutants.out"
    rm -rf "$out2"
    if [[ -s "$missed" ]]; then
        re=$(python3 -c 'import re,sys; print("^(" + "|".join(re.escape(l.rstrip("\n")) for l in open(sys.argv[1]) if l.strip()) + ")$")' "$missed")
        args=("${common[@]}" --output "target/mutants/$name-integration" --cargo-arg=--lib --re "$re")
        for t in $tests; do
            args+=("--cargo-arg=--test=$t")
        done
        echo "== $name tier 2 ($(wc -l <"$missed") missed by the unit tests): integration tests $tests"
        mkdir -p "target/mutants/$name-integration"
        cargo mutants "${args[@]}" -- -E "$filter" || true
    fi
    count() { if [[ -f "$1" ]]; then wc -l <"$1"; else echo 0; fi; }
    c1=$(count "$out/caught.txt")
    c2=$(count "$out2/caught.txt")
    printf '%s caught: %s (unit tests) + %s (integration tests)\n' "$name" "$c1" "$c2"
    if [[ ! -s "$missed" ]]; then
        m=0
    elif [[ -f "$out2/outcomes.json" ]]; then
        m=$(count "$out2/missed.txt")
    else
        m="$(count "$missed") (tier 2 did not run)"
    fi
    printf '%s missed: %s\n' "$name" "$m"
    printf '%s timeout: %s\n' "$name" "$(( $(count "$out/timeout.txt") + $(count "$out2/timeout.txt") ))"
    printf '%s unviable: %s\n' "$name" "$(count "$out/unviable.txt")"
    [[ -s "$out2/missed.txt" ]] && { echo "$name still missed:"; cat "$out2/missed.txt"; }
done
