#!/usr/bin/env bash
# Mutation testing of segfem's physics modules with cargo-mutants (issue 42 item 4).
#
# Each module is mutated alone (`cargo mutants -f FILE`) and every mutant is run against the
# fast tests that cover that module: its unit tests in the library and one or two integration
# test binaries, never the whole suite. Builds are incremental in the repository's own
# release target (`--in-place`: cargo-mutants restores the file after each mutant and on
# Ctrl-C; if it is killed hard, `git checkout -- src/` restores the sources).
# Not for CI: a whole module takes hours on a 2-core machine (about 1–2 minutes of build and
# test per mutant; src/prestress/friction.rs alone has 352 mutants).
#
# Usage:
#   validation/mutants.sh                       # every module below, one after the other
#   validation/mutants.sh friction interface    # some modules
#   SHARD=0/16 validation/mutants.sh friction   # one 16th of the mutants (round robin)
#   validation/mutants.sh --list                # the modules, files and tests
#
# Results: target/mutants/<module>/mutants.out/{caught,missed,timeout,unviable}.txt and
# outcomes.json; the last lines of each run give the counts. Record the figures, with the date,
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
    "tendon|src/elements/tendon.rs|tendons|test(/^elements::tendon::/) | binary(tendons)"
    "thermal|src/elements/thermal.rs|thermal|test(/^elements::thermal::/) | binary(thermal)"
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
    args=(--in-place --profile release --test-tool nextest --no-shuffle
        --timeout 300 --output "target/mutants/$name" --cargo-arg=--lib)
    for t in $tests; do
        args+=("--cargo-arg=--test=$t")
    done
    for f in $files; do
        args+=(-f "$f")
    done
    if [[ -n "${SHARD:-}" ]]; then
        args+=(--shard "$SHARD" --sharding round-robin)
    fi
    mkdir -p "target/mutants/$name"
    echo "== $name ($(date -u +%F)): cargo mutants ${args[*]} -- -E '$filter'"
    # Missed mutants make cargo-mutants exit non-zero: carry on with the next module.
    cargo mutants "${args[@]}" -- -E "$filter" || true
    out="target/mutants/$name/mutants.out"
    for k in caught missed timeout unviable; do
        printf '%s %s: %s\n' "$name" "$k" "$(wc -l <"$out/$k.txt" 2>/dev/null || echo 0)"
    done
done
