#!/usr/bin/env bash
# Instruction counts (valgrind callgrind, one thread; the VM has no hardware counters for
# perf) of a Newton iteration on the RC beam, segfem against OpenSees: each program runs
# the first increments of the cracking step twice, with N1 and N2 increments, and the
# difference of the instruction counts over the difference of the iteration counts is the
# cost of one iteration (set-up, input and start-up cancel). Needs bench/peers/nonlinear.py
# to have written bench/peers/work/nl_beam_1 first (python3 bench/peers/nonlinear.py
# --only beam --rounds 1 does).
#     bench/peers/callgrind_beam.sh [N1 N2]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
w="$here/work/cg_beam"
mkdir -p "$w"
cp "$here/work/nl_beam_1/segfem.toml" "$here/work/nl_beam_1/opensees.py" "$w/"
seg="${CARGO_TARGET_DIR:-$here/../../target}/release/segfem"
n1="${1:-2}"; n2="${2:-8}"
cd "$w"
for n in "$n1" "$n2"; do
    # segfem: the cracking step only, n increments of the example's 0.02 mm.
    python3 - "$n" <<'PY'
import re, sys
n = int(sys.argv[1])
t = open("segfem.toml").read()
t = t[: t.index('[[steps]]\nname = "to_failure"')]
t = t.replace('value = -0.0005 }\nincrements = 25', f'value = {-0.00002 * n!r} }}\nincrements = {n}')
open(f"cg_segfem_{n}.toml", "w").write(t)
s = open("opensees.py").read()
s = s.replace("okk = run(-0.0005, 25) and run(-0.0235, 120)", f"okk = run({-0.00002 * n!r}, {n})")
open(f"cg_opensees_{n}.py", "w").write(s)
PY
    valgrind --tool=callgrind --callgrind-out-file="cg_segfem_$n.out" "$seg" run -q --threads 1 "cg_segfem_$n.toml" -o "cg_segfem_out_$n" > /dev/null 2> "cg_segfem_$n.log"
    its=$(python3 -c "import csv; print(sum(int(r['iterations']) for r in csv.DictReader(open('cg_segfem_out_$n/history.csv'))))")
    echo "segfem $n increments: $its iterations, $(grep -o 'Collected : [0-9]*' "cg_segfem_$n.log") instructions"
    OMP_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file="cg_opensees_$n.out" "$here/.venv/bin/python" "cg_opensees_$n.py" > /dev/null 2> "cg_opensees_$n.log"
    its=$(python3 -c "import json; print(json.load(open('opensees_result.json'))['iterations'])")
    echo "OpenSees $n increments: $its iterations, $(grep -o 'Collected : [0-9]*' "cg_opensees_$n.log") instructions"
done
