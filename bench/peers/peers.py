#!/usr/bin/env python3
"""Side-by-side benchmark of segfem against OpenSees, CalculiX and OOFEM (issue 9).

Writes the same problems in each program's input under bench/peers/work/ (git-ignored),
runs every program on every problem A B A B (several rounds, programs interleaved so that
slow drifts of the machine hit all of them alike), and prints a table of the median wall
time, the peak resident memory (from /usr/bin/time -v) and the result value each program
reports, with the relative difference from segfem's value so that equal answers are
checked, not assumed.

    bench/peers/install.sh                      # once: ccx (apt), OpenSees and OOFEM (venv)
    python3 bench/peers/peers.py                # all problems, default sizes and rounds
    python3 bench/peers/peers.py --only q4 --sizes 1e4,1e5 --rounds 3
    python3 bench/peers/peers.py --only q4 --sizes 1e6 --programs OpenSees --opensees-system SparseSYM
    python3 bench/peers/peers.py --only q4 --sizes 5e5 --modes one     # one core only

Each peer runs its fastest solver, found by timing every candidate at each size
(--opensees-system auto, --ccx-solver auto), and every program runs pinned to one core with
one thread ("one") and on all cores ("all"); the table gives wall and CPU time of both.

The nonlinear side by side (RC panel and beam) is bench/peers/nonlinear.py; the scaling
figure bench/peers/scaling.py.

Problems (element formulations matched, see docs/performance.md):
  q4, q8     linear plane stress: unit square, left edge clamped, uniform shear load on the
             right edge; u_y at the top-right corner. segfem, OpenSees, CalculiX.
  contact    two blocks pressed together across a dry joint with Coulomb friction, one
             pushed along the joint until it slides; the sliding force. segfem, OpenSees,
             CalculiX.
  creep      one element under constant stress for 10^4 days; the strain. segfem, OOFEM.
"""

import argparse
import inspect
import json
import math
import os
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
WORK = HERE / "work"
VENV_PY = HERE / ".venv" / "bin" / "python"

# OpenSees' linear solver on the squares (--opensees-system): "auto" times every candidate
# once at each size (one core) and keeps the fastest that gives the right answer (UmfPack
# fails at 1e6 dofs: its displacement stays 0). OpenSees takes BLAS and LAPACK from the
# system's libblas.so.3 / liblapack.so.3, which install.sh points at OpenBLAS.
OPENSEES_SYSTEM = "auto"
OPENSEES_CANDIDATES = ("UmfPack", "SparseSYM", "SuperLU", "Mumps")
# The numberer each system is run with: UmfPack, SuperLU and Mumps order the matrix
# themselves; SparseSYM and the profile/band systems take RCM.
OPENSEES_NUMBERER = {"UmfPack": "Plain", "SuperLU": "Plain", "Mumps": "Plain"}
# CalculiX's *STATIC solvers this build has (PARDISO and PaStiX are not linked in Debian's
# ccx 2.20); "auto" keeps the fastest, as for OpenSees.
CCX_CANDIDATES = ("SPOOLES", "ITERATIVE CHOLESKY")
CCX_SOLVER = "auto"
# A time limit [s] on each timed process (None: none); set while candidates are selected.
TIMEOUT = None

# How the programs may use the machine (--modes): "one" pins every process to one core with
# one thread (taskset -c 0 and every thread-count variable at 1); "all" lets each program use
# every core (its threads at the core count). None: the environment as it is (nonlinear.py,
# scaling.py).
MODE = None
THREAD_VARS = ("RAYON_NUM_THREADS", "OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "CCX_NPROC_EQUATION_SOLVER")


def mode_env_and_prefix(mode):
    """The environment and command prefix of a run mode (see MODE)."""
    env = dict(os.environ)
    if mode is None:
        return env, []
    threads = "1" if mode == "one" else str(os.cpu_count() or 1)
    env.update({v: threads for v in THREAD_VARS})
    return env, (["taskset", "-c", "0"] if mode == "one" else [])

# Material and load of the linear square (docs/performance.md, side by side): E [Pa], nu, t [m], total
# shear force on the right edge [N].
E, NU, T = 30e9, 0.2, 0.2
P_TOTAL = -1.0e5


def segfem_bin():
    target = os.environ.get("CARGO_TARGET_DIR", str(REPO / "target"))
    return Path(target) / "release" / "segfem"


# ---------------------------------------------------------------------------------------
# Meshes: the structured square of segfem's banded mesh, numbered the same way everywhere
# (row by row from the bottom; Q8 has no centre nodes).
# ---------------------------------------------------------------------------------------


def square_mesh(kind, n, x0=0.0, width=1.0, height=1.0):
    """Nodes [(x, y)] and elements [node indices, VTK/Abaqus order] of an n x n mesh."""
    nodes, index = [], {}
    if kind == "Q4":
        for j in range(n + 1):
            for i in range(n + 1):
                index[(i, j)] = len(nodes)
                nodes.append((x0 + width * i / n, height * j / n))
        elems = [
            [index[(i, j)], index[(i + 1, j)], index[(i + 1, j + 1)], index[(i, j + 1)]]
            for j in range(n)
            for i in range(n)
        ]
    else:
        m = 2 * n
        for j in range(m + 1):
            for i in range(m + 1):
                if i % 2 == 1 and j % 2 == 1:
                    continue  # no centre node in a serendipity element
                index[(i, j)] = len(nodes)
                nodes.append((x0 + width * i / m, height * j / m))
        elems = []
        for j in range(0, m, 2):
            for i in range(0, m, 2):
                c = [(i, j), (i + 2, j), (i + 2, j + 2), (i, j + 2)]
                mid = [(i + 1, j), (i + 2, j + 1), (i + 1, j + 2), (i, j + 1)]
                elems.append([index[p] for p in c + mid])
    return nodes, elems


def edge_nodal_forces(kind, n, total):
    """Consistent nodal forces of a uniform load `total` on an edge of n elements,
    as a list along the edge (Q4: n+1 nodes, Q8: 2n+1 nodes)."""
    h = 1.0 / n
    q = total  # per unit length of a unit edge
    if kind == "Q4":
        f = [0.0] * (n + 1)
        for e in range(n):
            f[e] += q * h / 2
            f[e + 1] += q * h / 2
    else:
        f = [0.0] * (2 * n + 1)
        for e in range(n):
            f[2 * e] += q * h / 6
            f[2 * e + 1] += 2 * q * h / 3
            f[2 * e + 2] += q * h / 6
    return f


def q8_n_for(dofs):
    return max(2, round(math.sqrt(dofs / 6.0)))


def q4_n_for(dofs):
    return max(2, round(math.sqrt(dofs / 2.0)) - 1)


# ---------------------------------------------------------------------------------------
# Linear square: writers
# ---------------------------------------------------------------------------------------


def write_linear(kind, n, d, ops_system=None, ccx_solver="SPOOLES"):
    """The square in each program's input under d; `ops_system` (OpenSees' system, default
    OPENSEES_SYSTEM) and `ccx_solver` (CalculiX's *STATIC solver) name the peers' files
    (opensees_<system>.py, ccx_<solver>.inp) so that every candidate can be timed."""
    # Outside peers.py's selection (scaling.py): the given system, or UmfPack for "auto".
    ops_system = ops_system or (OPENSEES_SYSTEM if OPENSEES_SYSTEM != "auto" else "UmfPack")
    d.mkdir(parents=True, exist_ok=True)
    nodes, elems = square_mesh(kind, n)
    per_row = n + 1 if kind == "Q4" else 2 * n + 1
    # Right edge nodes bottom to top, left edge nodes.
    right = [i for i, (x, y) in enumerate(nodes) if abs(x - 1.0) < 1e-12]
    right.sort(key=lambda i: nodes[i][1])
    left = [i for i, (x, y) in enumerate(nodes) if abs(x) < 1e-12]
    forces = edge_nodal_forces(kind, n, P_TOTAL)
    assert len(right) == len(forces) == per_row
    tip = right[-1]
    files = {}
    # segfem: banded mesh, line load (consistent forces computed by segfem itself).
    (d / "segfem.toml").write_text(
        f"""title = "square {kind} {n}x{n}"
[[materials]]
name = "m"
kind = "elastic"
E = {E!r}
nu = {NU!r}
[[regions]]
name = "r"
material = "m"
thickness = {T!r}
[mesh]
type = "banded"
length = 1.0
nx = {n}
element = "{kind}"
bands = [{{ region = "r", depth = 1.0, rows = {n} }}]
[[supports]]
name = "wall"
line = [[0.0, 0.0], [0.0, 1.0]]
ux = 0.0
uy = 0.0
[[load_cases]]
name = "shear"
line_loads = [{{ line = [[1.0, 0.0], [1.0, 1.0]], q = [0.0, {P_TOTAL!r}] }}]
[[monitors]]
name = "tip_uy"
kind = "displacement"
point = [1.0, 1.0]
component = "y"
[[steps]]
name = "load"
kind = "linear"
loads = {{ shear = 1.0 }}
"""
    )
    files["segfem + .vtu"] = d / "segfem.toml"
    # The same run writing only what the peers write (the answer: history.csv and
    # summary.json, besides its checkpoint), `output = "none"`: the output volume matched.
    text = (d / "segfem.toml").read_text()
    (d / "segfem_monitors.toml").write_text(text + 'output = "none"\n')
    files["segfem"] = d / "segfem_monitors.toml"
    # CalculiX: CPS4 / CPS8 (plane stress), `ccx_solver`, the tip displacement printed to .dat.
    etype = "CPS4" if kind == "Q4" else "CPS8"
    ccx_file = d / f"ccx_{ccx_solver.replace(' ', '_').lower()}.inp"
    with open(ccx_file, "w") as f:
        f.write("*NODE, NSET=NALL\n")
        f.writelines(f"{i + 1},{x!r},{y!r}\n" for i, (x, y) in enumerate(nodes))
        f.write(f"*ELEMENT, TYPE={etype}, ELSET=EALL\n")
        f.writelines(
            f"{k + 1}," + ",".join(str(v + 1) for v in e) + "\n" for k, e in enumerate(elems)
        )
        f.write("*NSET, NSET=LEFT\n")
        f.writelines(f"{i + 1}\n" for i in left)
        f.write(f"*NSET, NSET=TIP\n{tip + 1}\n")
        f.write(f"*MATERIAL, NAME=M\n*ELASTIC\n{E!r},{NU!r}\n")
        f.write(f"*SOLID SECTION, ELSET=EALL, MATERIAL=M\n{T!r}\n")
        f.write("*BOUNDARY\nLEFT,1,2\n")
        f.write(f"*STEP\n*STATIC, SOLVER={ccx_solver}\n*CLOAD\n")
        f.writelines(f"{i + 1},2,{fy!r}\n" for i, fy in zip(right, forces) if fy != 0.0)
        f.write("*NODE PRINT, NSET=TIP\nU\n*END STEP\n")
    files["CalculiX"] = ccx_file
    # OpenSees: quad / quad8n PlaneStress, `ops_system` (chosen by measurement at each size,
    # `--opensees-system auto`). The script builds the mesh with the same generator, as a
    # user's script would (not from a literal list, which Python would be slow to parse).
    ele = "quad" if kind == "Q4" else "quad8n"
    ops_file = d / f"opensees_{ops_system.lower()}.py"
    with open(ops_file, "w") as f:
        f.write(
            "import openseespy.opensees as ops\n"
            + inspect.getsource(square_mesh)
            + inspect.getsource(edge_nodal_forces)
            + f"nodes, elems = square_mesh('{kind}', {n})\n"
            f"forces = edge_nodal_forces('{kind}', {n}, {P_TOTAL!r})\n"
            "right = sorted((i for i, (x, y) in enumerate(nodes) if abs(x - 1.0) < 1e-12), key=lambda i: nodes[i][1])\n"
            "ops.wipe()\nops.model('basic', '-ndm', 2, '-ndf', 2)\n"
            f"ops.nDMaterial('ElasticIsotropic', 1, {E!r}, {NU!r})\n"
            "for i, (x, y) in enumerate(nodes):\n    ops.node(i + 1, x, y)\n"
            "    if abs(x) < 1e-12:\n        ops.fix(i + 1, 1, 1)\n"
            "for k, e in enumerate(elems):\n"
            f"    ops.element('{ele}', k + 1, *[v + 1 for v in e], {T!r}, 'PlaneStress', 1)\n"
            "ops.timeSeries('Linear', 1)\nops.pattern('Plain', 1, 1)\n"
            "for i, fy in zip(right, forces):\n"
            "    if fy != 0.0:\n        ops.load(i + 1, 0.0, fy)\n"
            f"ops.system('{ops_system}')\nops.numberer('{OPENSEES_NUMBERER.get(ops_system, 'RCM')}')\nops.constraints('Plain')\n"
            "ops.integrator('LoadControl', 1.0)\nops.algorithm('Linear')\n"
            "ops.analysis('Static')\nassert ops.analyze(1) == 0, 'analysis failed'\n"
            "print('RESULT', repr(ops.nodeDisp(right[-1] + 1, 2)))\n"
        )
    files["OpenSees"] = ops_file
    return files


# ---------------------------------------------------------------------------------------
# Contact: two blocks, dry joint with Coulomb friction, pushed along the joint until slip
# ---------------------------------------------------------------------------------------

# Block size 1 m x 1 m, n x n Q4 each; joint at x = 1. Block A clamped on its left edge;
# block B's right edge pushed to ux = UX_PUSH (normal force N across the joint), then moved
# down to uy = UY_SLIDE (20 increments), well past the onset of sliding. Result: the ratio
# of the vertical to the horizontal force on B's right edge at the end, = mu when the whole
# joint slides, whatever the penalties. The same penalties everywhere: KN, KT [Pa/m].
MU, KN, KT = 0.6, 3.0e13, 1.25e13
UX_PUSH, UY_SLIDE, N_SLIDE = -6.7e-5, -1.0e-3, 20


def write_contact(n, d):
    d.mkdir(parents=True, exist_ok=True)
    na, ea = square_mesh("Q4", n)
    nb, eb = square_mesh("Q4", n, x0=1.0)
    off = len(na)
    nodes = na + nb
    elems = ea + [[v + off for v in e] for e in eb]
    left = [i for i, (x, y) in enumerate(na) if abs(x) < 1e-12]
    right = [i + off for i, (x, y) in enumerate(nb) if abs(x - 2.0) < 1e-12]
    ja = sorted((i for i, (x, y) in enumerate(na) if abs(x - 1.0) < 1e-12), key=lambda i: na[i][1])
    jb = sorted((i + off for i, (x, y) in enumerate(nb) if abs(x - 1.0) < 1e-12), key=lambda i: nodes[i][1])
    files = {}
    (d / "segfem.toml").write_text(
        f"""title = "two blocks, dry joint, sliding"
[[materials]]
name = "m"
kind = "elastic"
E = {E!r}
nu = {NU!r}
[[regions]]
name = "r"
material = "m"
thickness = {T!r}
[[joint_materials]]
name = "dry"
kind = "dry"
friction = {MU!r}
kn = {KN!r}
kt = {KT!r}
[mesh]
type = "segmental"
segments = [1.0, 1.0]
nx_per_segment = {n}
element = "Q4"
joint_material = "dry"
bands = [{{ region = "r", depth = 1.0, rows = {n} }}]
[[supports]]
name = "wall"
line = [[0.0, 0.0], [0.0, 1.0]]
ux = 0.0
uy = 0.0
[[supports]]
name = "push"
line = [[2.0, 0.0], [2.0, 1.0]]
ux = {UX_PUSH!r}
[[monitors]]
name = "N"
kind = "reaction"
support = "push"
component = "x"
[[monitors]]
name = "R_wall_y"
kind = "reaction"
support = "wall"
component = "y"
[[steps]]
name = "press"
kind = "load"
[[steps]]
name = "slide"
kind = "displacement"
control = {{ line = [[2.0, 0.0], [2.0, 1.0]], component = "y", value = {UY_SLIDE!r} }}
increments = {N_SLIDE}
"""
    )
    files["segfem + .vtu"] = d / "segfem.toml"
    # The same run writing only what the peers write (the answer: history.csv and
    # summary.json, besides its checkpoint), `output = "none"`: the output volume matched.
    text = (d / "segfem.toml").read_text()
    (d / "segfem_monitors.toml").write_text(text + 'output = "none"\n')
    files["segfem"] = d / "segfem_monitors.toml"
    h = 1.0 / n
    trib = [h / 2 if k in (0, n) else h for k in range(n + 1)]
    with open(d / "opensees.py", "w") as f:
        f.write(
            "import openseespy.opensees as ops\n"
            "ops.wipe()\nops.model('basic', '-ndm', 2, '-ndf', 2)\n"
            f"ops.nDMaterial('ElasticIsotropic', 1, {E!r}, {NU!r})\n"
            f"nodes = {nodes!r}\nelems = {elems!r}\n"
            "for i, (x, y) in enumerate(nodes):\n    ops.node(i + 1, x, y)\n"
            "for k, e in enumerate(elems):\n"
            f"    ops.element('quad', k + 1, *[v + 1 for v in e], {T!r}, 'PlaneStress', 1)\n"
            f"for i in {left!r}:\n    ops.fix(i + 1, 1, 1)\n"
            # Node-to-node contact at the joint: B's node constrained, A's retained; the
            # penalties are the joint's per unit area times the node's tributary area.
            f"for k, (a, b, w) in enumerate(zip({ja!r}, {jb!r}, {trib!r})):\n"
            f"    ops.element('zeroLengthContact2D', len(elems) + k + 1, b + 1, a + 1, {KN!r} * w * {T!r}, "
            f"{KT!r} * w * {T!r}, {MU!r}, '-normal', 1.0, 0.0)\n"
            "ops.timeSeries('Linear', 1)\nops.pattern('Plain', 1, 1)\n"
            f"for i in {right!r}:\n    ops.sp(i + 1, 1, {UX_PUSH!r})\n    ops.sp(i + 1, 2, 0.0)\n"
            "ops.system('UmfPack')\nops.numberer('RCM')\nops.constraints('Transformation')\n"
            "ops.test('NormUnbalance', 1e-3, 50)\nops.algorithm('Newton')\n"
            "ops.integrator('LoadControl', 1.0)\nops.analysis('Static')\n"
            "assert ops.analyze(1) == 0\n"
            "ops.loadConst('-time', 0.0)\n"
            "ops.remove('loadPattern', 1)\n"
            "ops.timeSeries('Linear', 2)\nops.pattern('Plain', 2, 2)\n"
            f"for i in {right!r}:\n    ops.sp(i + 1, 1, {UX_PUSH!r})\n    ops.sp(i + 1, 2, {UY_SLIDE!r})\n"
            f"ops.integrator('LoadControl', {1.0 / N_SLIDE!r})\n"
            f"assert ops.analyze({N_SLIDE}) == 0\n"
            "ops.reactions()\n"
            f"fx = sum(ops.nodeReaction(i + 1, 1) for i in {right!r})\n"
            f"fy = sum(ops.nodeReaction(i + 1, 2) for i in {right!r})\n"
            "print('RESULT', repr(abs(fy / fx)))\n"
        )
    files["OpenSees"] = d / "opensees.py"
    with open(d / "ccx.inp", "w") as f:
        f.write("*NODE, NSET=NALL\n")
        f.writelines(f"{i + 1},{x!r},{y!r}\n" for i, (x, y) in enumerate(nodes))
        f.write("*ELEMENT, TYPE=CPS4, ELSET=EALL\n")
        f.writelines(f"{k + 1}," + ",".join(str(v + 1) for v in e) + "\n" for k, e in enumerate(elems))
        # Faces at the joint: A's last column (face 2: nodes 2-3), B's first (face 4: 4-1).
        ne = len(ea)
        f.write("*SURFACE, NAME=SA, TYPE=ELEMENT\n")
        f.writelines(f"{j * n + n},S2\n" for j in range(n))
        f.write("*SURFACE, NAME=SB, TYPE=ELEMENT\n")
        f.writelines(f"{ne + j * n + 1},S4\n" for j in range(n))
        f.write("*NSET, NSET=LEFT\n" + "".join(f"{i + 1}\n" for i in left))
        f.write("*NSET, NSET=RIGHT\n" + "".join(f"{i + 1}\n" for i in right))
        f.write(f"*MATERIAL, NAME=M\n*ELASTIC\n{E!r},{NU!r}\n")
        f.write(f"*SOLID SECTION, ELSET=EALL, MATERIAL=M\n{T!r}\n")
        f.write(f"*SURFACE INTERACTION, NAME=SI\n*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n{KN!r}\n")
        f.write(f"*FRICTION\n{MU!r},{KT!r}\n")
        f.write("*CONTACT PAIR, INTERACTION=SI, TYPE=SURFACE TO SURFACE\nSB,SA\n")
        f.write("*BOUNDARY\nLEFT,1,2\n")
        f.write(f"*STEP\n*STATIC\n1.,1.\n*BOUNDARY\nRIGHT,1,1,{UX_PUSH!r}\nRIGHT,2,2,0.\n*END STEP\n")
        f.write(f"*STEP, INC=1000\n*STATIC\n{1.0 / N_SLIDE!r},1.\n*BOUNDARY\nRIGHT,1,1,{UX_PUSH!r}\nRIGHT,2,2,{UY_SLIDE!r}\n")
        f.write("*NODE PRINT, NSET=RIGHT, TOTALS=ONLY\nRF\n*END STEP\n")
    files["CalculiX"] = d / "ccx.inp"
    return files


def ccx_total_ratio(dat):
    """|Fy / Fx| of the last force totals printed in a .dat file."""
    rows = re.findall(r"total force.*\n\s*\n?\s*(\S+)\s+(\S+)\s+(\S+)", dat)
    fx, fy, _ = (float(v) for v in rows[-1])
    return abs(fy / fx)


def contact_problem(n=20):
    d = WORK / f"contact_{n}"
    files = write_contact(n, d)

    def seg():
        wall, rss, ry, s = run_segfem(files["segfem"], "R_wall_y")
        nx = dict(s["final_monitors"])["N"]
        return wall, rss, abs(ry / nx)

    runners = {
        "segfem": seg,
        "OpenSees": lambda: run_python(files["OpenSees"]),
        "CalculiX": lambda: run_ccx(files["CalculiX"], ccx_total_ratio),
    }
    dofs = 2 * 2 * (n + 1) ** 2
    return f"two blocks sliding, {n}x{n} Q4 each, {dofs:,} dofs", "friction force / normal force", runners


# ---------------------------------------------------------------------------------------
# Creep: one element under constant uniaxial stress for 10^4 days
# ---------------------------------------------------------------------------------------

# Concrete fcm = 30 MPa (at most 35 MPa, where Eurocode 2's creep coefficient (Annex B) and
# MC90's coincide), RH 70 %, h0 = 200 mm, cement class N, no shrinkage; loaded at 28 days
# by sigma = -10 MPa, held to 28 + 10^4 days. segfem: `elastic_creep` (MC90 by an ageing
# Maxwell chain). OOFEM: `EC2CreepMat` (Eurocode 2 by a Kelvin chain; OOFEM's Maxwell-chain
# materials are B3, CEB-FIP 1978 and the double power law, none of them MC90). The two
# normalise the creep coefficient differently (MC90: phi / E_ci; EC2: phi / 1.05 E_cm), so
# the compared result is the creep coefficient recovered from each program's final strain
# with its own 28-day modulus (loading at 28 days):
#   segfem  J = (1 + phi) / E_ci,       E_ci = 21.5 GPa (fcm / 10 MPa)^(1/3)
#   OOFEM   J = (1 + phi / 1.05) / E_cm, E_cm = 22 GPa (fcm / 10 MPa)^0.3
FCM, RH, H0, SIGMA, T_LOAD, DURATION = 30e6, 0.7, 0.2, -10e6, 28.0, 1.0e4


def phi_mc90(t, t0, fcm=FCM, rh=RH, h0=H0):
    """MC90 creep coefficient (2.1-64 to 2.1-71), h0 in m, fcm in Pa."""
    h = h0 * 1000.0
    phi_rh = 1.0 + (1.0 - rh) / (0.46 * (h / 100.0) ** (1.0 / 3.0))
    beta_fcm = 5.3 / math.sqrt(fcm / 10e6)
    beta_t0 = 1.0 / (0.1 + t0**0.2)
    beta_h = min(150.0 * (1.0 + (1.2 * rh) ** 18) * h / 100.0 + 250.0, 1500.0)
    return phi_rh * beta_fcm * beta_t0 * ((t - t0) / (beta_h + t - t0)) ** 0.3


def write_creep(d):
    d.mkdir(parents=True, exist_ok=True)
    files = {}
    (d / "segfem.toml").write_text(
        f"""title = "creep of one element under constant stress"
[[materials]]
name = "c"
kind = "elastic_creep"
fcm = {FCM!r}
rh = {RH!r}
h0 = {H0!r}
cement = "N"
nu = 0.2
shrinkage = false
[[regions]]
name = "r"
material = "c"
thickness = 1.0
[mesh]
type = "explicit"
nodes = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
[[mesh.blocks]]
region = "r"
element = "Q4"
elements = [[1, 2, 3, 4]]
[[supports]]
name = "left"
line = [[0.0, 0.0], [0.0, 1.0]]
ux = 0.0
[[supports]]
name = "pin"
node = 1
uy = 0.0
[[load_cases]]
name = "axial"
line_loads = [{{ line = [[1.0, 0.0], [1.0, 1.0]], q = [{SIGMA!r}, 0.0] }}]
[[monitors]]
name = "ux"
kind = "displacement"
node = 2
component = "x"
[[steps]]
name = "load"
kind = "load"
loads = {{ axial = 1.0 }}
[[steps]]
name = "creep"
kind = "time"
from = {T_LOAD!r}
duration = {DURATION!r}
"""
    )
    files["segfem + .vtu"] = d / "segfem.toml"
    # The same run writing only what the peers write (the answer: history.csv and
    # summary.json, besides its checkpoint), `output = "none"`: the output volume matched.
    text = (d / "segfem.toml").read_text()
    (d / "segfem_monitors.toml").write_text(text + 'output = "none"\n')
    files["segfem"] = d / "segfem_monitors.toml"
    times = " ".join(repr(x) for x in [1e-4 * 10 ** (k / 5.0) for k in range(41)])
    (d / "oofem.in").write_text(
        f"""oofem.out
creep of one element under constant stress
IncrLinearStatic endOfTimeOfInterest {DURATION!r} prescribedTimes 41 {times} nmodules 0
domain 2dPlaneStress
OutputManager tstep_all dofman_all
ndofman 4 nelem 1 ncrosssect 1 nmat 1 nbc 2 nic 0 nltf 1
node 1 coords 3 0.0 0.0 0.0 bc 2 1 1
node 2 coords 3 1.0 0.0 0.0 load 1 2
node 3 coords 3 1.0 1.0 0.0 load 1 2
node 4 coords 3 0.0 1.0 0.0 bc 2 1 0
planestress2d 1 nodes 4 1 2 3 4 crossSect 1 mat 1
SimpleCS 1 thick 1.0 width 1.0
EC2CreepMat 1 d 0. n 0.2 fcm28 {FCM / 1e6!r} stiffnessFactor 1.e6 relMatAge {T_LOAD!r} t0 7. timeFactor 1. cemType 2 henv {RH!r} h0 {H0 * 1000!r} shType 0 begOfTimeOfInterest 1.e-4 endOfTimeOfInterest {DURATION!r}
BoundaryCondition 1 loadTimeFunction 1 prescribedvalue 0.
NodalLoad 2 loadTimeFunction 1 Components 2 {SIGMA / 1e6 / 2!r} 0.
ConstantFunction 1 f(t) 1.0
"""
    )
    (d / "oofem_run.py").write_text(
        "import re, oofem\n"
        "dr = oofem.OOFEMTXTDataReader('oofem.in')\n"
        "pb = oofem.InstanciateProblem(dr, oofem.problemMode.processor, 0, None, False)\n"
        "pb.checkProblemConsistency()\npb.setRenumberFlag()\npb.solveYourself()\npb.terminateAnalysis()\n"
        "out = open('oofem.out').read()\n"
        "u = [float(v) for v in re.findall(r'Node\\s+2\\s+\\(\\s*2\\):\\s*\\n\\s*dof 1\\s+d\\s+(\\S+)', out)]\n"
        f"ecm = 22e9 * ({FCM!r} / 10e6) ** 0.3\n"
        f"print('RESULT', repr(1.05 * (u[-1] / {SIGMA!r} * ecm - 1.0)))\n"
    )
    files["OOFEM"] = d / "oofem_run.py"
    return files


def creep_problem():
    d = WORK / "creep"
    files = write_creep(d)

    def seg():
        wall, rss, ux, s = run_segfem(files["segfem"], "ux")
        eci = 21.5e9 * (FCM / 10e6) ** (1.0 / 3.0)
        return wall, rss, ux / SIGMA * eci - 1.0

    runners = {"segfem": seg, "OOFEM": lambda: run_python(files["OOFEM"])}
    ref = phi_mc90(T_LOAD + DURATION, T_LOAD)
    return f"one element, creep 10^4 d (MC90 phi = {ref:.4f})", "creep coefficient phi", runners


# ---------------------------------------------------------------------------------------
# Running and parsing
# ---------------------------------------------------------------------------------------


# CPU seconds (user + system) of each timed process, in order (read by `bench`).
CPU_TIMES = []


def timed(cmd, cwd, ok=(0,)):
    """Run cmd under /usr/bin/time -v; return (wall s, peak RSS bytes, stdout, stderr).
    An exit status outside `ok` is an error."""
    env, prefix = mode_env_and_prefix(MODE)
    t0 = time.perf_counter()
    p = subprocess.run(
        prefix + ["/usr/bin/time", "-v"] + [str(c) for c in cmd],
        cwd=cwd,
        capture_output=True,
        text=True,
        env=env,
        timeout=TIMEOUT,
    )
    wall = time.perf_counter() - t0
    m = re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr)
    rss = int(m.group(1)) * 1024 if m else None
    cpu = sum(float(v) for v in re.findall(r"(?:User|System) time \(seconds\): (\S+)", p.stderr))
    CPU_TIMES.append(cpu)
    if p.returncode not in ok:
        raise RuntimeError(f"{cmd} in {cwd} failed ({p.returncode}):\n{p.stdout[-2000:]}\n{p.stderr[-2000:]}")
    return wall, rss, p.stdout, p.stderr


def run_segfem(path, monitor):
    out = path.parent / f"{path.stem}_out"
    wall, rss, _, _ = timed([segfem_bin(), "run", path.name, "-o", out.name], path.parent)
    s = json.loads((out / "summary.json").read_text())
    vals = dict(s["final_monitors"])
    return wall, rss, vals[monitor], s


def run_python(path):
    wall, rss, out, _ = timed([VENV_PY, path.name], path.parent)
    m = re.findall(r"^RESULT (\S+)", out, re.M)
    if not m:
        raise RuntimeError(f"{path}: no RESULT line in\n{out[-2000:]}")
    return wall, rss, float(m[-1])


def run_ccx(path, parse):
    job = path.stem
    for ext in (".dat", ".frd", ".sta", ".cvg", ".12d"):
        (path.parent / (job + ext)).unlink(missing_ok=True)
    # Outside a run mode, one OpenMP thread (as before the modes).
    env_cmd = (["env", "OMP_NUM_THREADS=1"] if MODE is None else []) + ["ccx", "-i", job]
    wall, rss, out, _ = timed(env_cmd, path.parent)
    return wall, rss, parse((path.parent / (job + ".dat")).read_text())


def ccx_last_u(dat, comp=2):
    """Last nodal displacement component printed in a .dat file."""
    rows = re.findall(r"^\s+\d+\s+(\S+)\s+(\S+)\s+(\S+)\s*$", dat, re.M)
    return float(rows[-1][comp - 1])


# ---------------------------------------------------------------------------------------
# Benchmark loop
# ---------------------------------------------------------------------------------------


def linear_problem(kind, dofs):
    """The square near `dofs` unknowns; each peer's runners, one per solver candidate (the
    fastest is kept by `select`)."""
    n = q4_n_for(dofs) if kind == "Q4" else q8_n_for(dofs)
    d = WORK / f"{kind.lower()}_{n}"
    ops = OPENSEES_CANDIDATES if OPENSEES_SYSTEM == "auto" else (OPENSEES_SYSTEM,)
    ccx = CCX_CANDIDATES if CCX_SOLVER == "auto" else (CCX_SOLVER,)
    runners = {"segfem": {}, "segfem + .vtu": {}, "OpenSees": {}, "CalculiX": {}}
    for i in range(max(len(ops), len(ccx))):
        files = write_linear(kind, n, d, ops[min(i, len(ops) - 1)], ccx[min(i, len(ccx) - 1)])
        for prog in ("segfem", "segfem + .vtu"):
            runners[prog][""] = lambda f=files[prog]: run_segfem(f, "tip_uy")[:3]
        runners["OpenSees"][ops[min(i, len(ops) - 1)]] = lambda f=files["OpenSees"]: run_python(f)
        runners["CalculiX"][ccx[min(i, len(ccx) - 1)]] = lambda f=files["CalculiX"]: run_ccx(f, ccx_last_u)
    nodes = (n + 1) ** 2 if kind == "Q4" else (2 * n + 1) ** 2 - n * n
    return f"{kind} {n}x{n} square, {2 * nodes:,} dofs", "tip u_y [m]", runners


def select(name, runners, tol, timeout):
    """Each program's fastest candidate (solver) on this problem: every candidate run once on
    one core (MODE "one"), kept if it ends within `timeout` [s] with segfem's answer (within
    the problem's tolerance); returns {label: runner} with labels "OpenSees (UmfPack)"."""
    global MODE, TIMEOUT
    MODE, TIMEOUT = "one", timeout
    chosen = {}
    try:
        _, _, ref = runners["segfem"][""]()
        for prog, cands in runners.items():
            if prog.startswith("segfem") or len(cands) == 1:
                for label, run in cands.items():
                    chosen[f"{prog} ({label})" if label else prog] = run
                continue
            best = None
            for label, run in cands.items():
                try:
                    wall, _, value = run()
                except (RuntimeError, subprocess.TimeoutExpired) as e:
                    print(f"  {name}: {prog} {label}: left out ({str(e).splitlines()[0][:120]})", file=sys.stderr, flush=True)
                    continue
                rel = abs(value - ref) / max(abs(ref), 1e-300)
                ok = rel <= tol.get(prog, tol["*"])
                print(f"  {name}: {prog} {label}: {wall:.3f} s, {value!r} ({'agrees' if ok else 'WRONG, left out'})", file=sys.stderr, flush=True)
                if ok and (best is None or wall < best[0]):
                    best = (wall, label, run)
            if best is not None:
                chosen[f"{prog} ({best[1]})"] = best[2]
    finally:
        MODE, TIMEOUT = None, None
    return chosen


def bench(name, unit, runners, rounds, skip_slow_after, modes):
    """A B A B: every round runs each program once per mode, in the same order."""
    global MODE
    rows = {(p, m): {"wall": [], "cpu": [], "rss": [], "value": None} for p in runners for m in modes}
    try:
        for r in range(rounds):
            for mode in modes:
                MODE = mode
                for prog, run in runners.items():
                    row = rows[(prog, mode)]
                    if r > 0 and row["wall"] and min(row["wall"]) > skip_slow_after:
                        continue  # a very slow peer: fewer repetitions (the count is reported)
                    wall, rss, value = run()
                    row["wall"].append(wall)
                    row["cpu"].append(CPU_TIMES[-1])
                    row["rss"].append(rss or 0)
                    row["value"] = value
                    print(f"  {name}: {prog} [{mode}] round {r + 1}: {wall:.3f} s, {value!r}", file=sys.stderr, flush=True)
    finally:
        MODE = None
    return rows


def report(name, unit, rows, tol, modes):
    """Table rows: per program, the medians of wall and CPU time in each mode, peak memory,
    the answer against segfem's and the fastest peer's time over segfem's: each program at
    its best, the least median wall and the least median CPU time over the modes that ran
    (OpenSees' all-core wall can exceed its one-core wall: OpenBLAS's second thread spins)."""
    progs = list(dict.fromkeys(p for p, _ in rows))
    med = {k: (statistics.median(v["wall"]), statistics.median(v["cpu"])) for k, v in rows.items()}
    seg = "segfem"
    ref = rows[(seg, modes[0])]["value"]
    # "segfem + .vtu" (the same run writing its field file too) is segfem, not a peer.
    peers_ = [p for p in progs if not p.startswith(seg)]
    best = {p: tuple(min(med[(p, m)][k] for m in modes) for k in (0, 1)) for p in progs}

    def over(a, b):
        # CPU times come in 10 ms steps (the kernel's accounting): a run below that reads 0.
        return "–" if b <= 0.0 else f"{a / b:.1f}"

    ratio_wall = over(min(best[p][0] for p in peers_), best[seg][0]) if peers_ else "–"
    ratio_cpu = over(min(best[p][1] for p in peers_), best[seg][1]) if peers_ else "–"
    lines = []
    for prog in progs:
        times = " | ".join(f"{med[(prog, m)][0]:.3f} | {med[(prog, m)][1]:.3f}" for m in modes)
        value = rows[(prog, modes[0])]["value"]
        rel = abs(value - ref) / max(abs(ref), 1e-300)
        base = prog.split(" (")[0]
        agree = "ref" if prog == seg else ("yes" if rel <= tol.get(base.split(" + ")[0], tol["*"]) else "NO")
        if prog == seg:
            speed = f"**{ratio_wall}× wall, {ratio_cpu}× CPU (each at its best mode)**"
        elif prog.startswith(seg) and peers_:
            fw = over(min(best[p][0] for p in peers_), best[prog][0])
            fc = over(min(best[p][1] for p in peers_), best[prog][1])
            speed = f"{fw}× wall, {fc}× CPU with its .vtu"
        else:
            speed = f"{over(best[prog][0], best[seg][0])} / {over(best[prog][1], best[seg][1])}"
        runs = min(len(rows[(prog, m)]["wall"]) for m in modes)
        rss = max(max(rows[(prog, m)]["rss"]) for m in modes)
        lines.append(
            f"| {name} | {prog} | {times} | {runs} | {rss / 2**20:.0f} | {value:.7g} | {rel:.1e} | {agree} | {speed} |"
        )
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", default="q4,q8,contact,creep", help="problems to run")
    ap.add_argument("--sizes", default="1e4,1e5,5e5,1e6", help="target dofs of the linear problems")
    ap.add_argument("--programs", default="", help="run only these programs (comma separated)")
    ap.add_argument("--rounds", type=int, default=3, help="A B A B rounds (medians are reported)")
    ap.add_argument(
        "--slow", type=float, default=60.0, help="a run slower than this [s] is not repeated"
    )
    ap.add_argument(
        "--modes", default="one,all",
        help="one: every program pinned to one core with one thread; all: every core (both by default)",
    )
    ap.add_argument(
        "--opensees-system", default="auto",
        help="OpenSees' system on the squares (auto: the fastest of " + ", ".join(OPENSEES_CANDIDATES) + " at each size, measured)",
    )
    ap.add_argument(
        "--ccx-solver", default="auto",
        help="CalculiX's solver on the squares (auto: the fastest of " + ", ".join(CCX_CANDIDATES) + ", measured)",
    )
    ap.add_argument(
        "--select-timeout", type=float, default=600.0,
        help="a solver candidate slower than this [s] is left out of the selection",
    )
    args = ap.parse_args()
    global OPENSEES_SYSTEM, CCX_SOLVER
    OPENSEES_SYSTEM, CCX_SOLVER = args.opensees_system, args.ccx_solver
    modes = args.modes.split(",")
    load0 = os.getloadavg()[0]
    if any(m not in ("one", "all") for m in modes):
        sys.exit(f"--modes {args.modes}: each mode is one or all")
    if "one" in modes and not shutil.which("taskset"):
        sys.exit("taskset not found (util-linux): needed for --modes one")
    if not segfem_bin().exists():
        sys.exit(f"{segfem_bin()} not found: cargo build --release first (CARGO_TARGET_DIR is honoured)")
    if not VENV_PY.exists() or not shutil.which("ccx"):
        sys.exit("peers not installed: run bench/peers/install.sh")
    WORK.mkdir(exist_ok=True)
    only = args.only.split(",")
    problems = []
    for kind in ("Q4", "Q8"):
        if kind.lower() in only:
            for s in args.sizes.split(","):
                # CalculiX's plane-stress elements are 3D bricks underneath (see
                # docs/performance.md): its answers differ by ~1e-3; OpenSees' quad/quad8n are segfem's.
                problems.append((linear_problem(kind, int(float(s))), {"*": 1e-6, "CalculiX": 3e-3}))
    if "contact" in only:
        # Sliding force / normal force = mu once the whole joint slides; CalculiX's
        # surface-to-surface contact converges to 3e-4 of it.
        problems.append((contact_problem(), {"*": 1e-3}))
    if "creep" in only:
        # Each program's chain approximates the creep function to ~1 %.
        problems.append((creep_problem(), {"*": 2e-2}))
    cols = " | ".join(f"{m} core{'s' if m == 'all' else ''}: wall [s] | CPU [s]" for m in modes)
    table = [
        f"| problem | program (solver) | {cols} | runs | peak memory [MiB] | result | rel. diff. | agrees | fastest peer / segfem |",
        "|---|---|" + "---|---|" * len(modes) + "---|---|---|---|---|---|",
    ]
    for (name, unit, runners), tol in problems:
        # Problems without solver candidates give one runner per program.
        runners = {p: (r if isinstance(r, dict) else {"": r}) for p, r in runners.items()}
        if args.programs:
            keep = args.programs.split(",")
            runners = {p: r for p, r in runners.items() if p in keep or p.startswith("segfem")}
        chosen = select(name, runners, tol, args.select_timeout)
        rows = bench(name, unit, chosen, args.rounds, args.slow, modes)
        table += report(f"{name}: {unit}", unit, rows, tol, modes)
        print("\n".join(table[-len(chosen):]), flush=True)
    print(f"\n{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {processor()}, load average at the start: {load0:.2f}, at the end: {os.getloadavg()[0]:.2f}")
    print("\n".join(table))


def processor():
    """The processor's model name and core count (for the table's heading)."""
    try:
        name = next(
            line.split(":", 1)[1].strip()
            for line in Path("/proc/cpuinfo").read_text().splitlines()
            if line.startswith("model name")
        )
    except (OSError, StopIteration):
        name = "unknown processor"
    return f"{name}, {os.cpu_count()} logical cores"


if __name__ == "__main__":
    main()
