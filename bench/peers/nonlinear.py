#!/usr/bin/env python3
"""Nonlinear side by side (issue 21 item 1): reinforced concrete in segfem and OpenSees.

Writes each problem in each program's input under bench/peers/work/ (git-ignored), runs
the programs in rounds A B A B, and prints per program: median wall and CPU time (user +
system, /usr/bin/time), Newton iterations, time per iteration, and the answers (cracking,
yield and peak load) with their difference from segfem's.

    bench/peers/install.sh && cargo build --release      # once
    python3 bench/peers/nonlinear.py                       # panel and beam, 3 rounds
    python3 bench/peers/nonlinear.py --only beam --rounds 2 --refine 1

OOFEM runs through its Python module from the inputs of bench/peers/oofem_beam.py
(--oofem-law fcm | idm1 | rcsd; --programs to leave a peer out).

Problems (docs/performance.md, "Nonlinear side by side", lists every difference of laws):
  panel  Vecchio-Collins PV19 (890 mm, 70 mm thick, f_c 19 MPa, rho_x 1.79 % f_y 458 MPa,
         rho_y 0.71 % f_y 299 MPa) in pure shear, n x n Q4, smeared steel in both programs.
         segfem: rotating cracks + Vecchio-Collins 1993 compression softening, arc length.
         OpenSees: ReinforcedConcretePlaneStress (Hsu-Zhong rotating-angle softened truss
         model: ConcreteL01, SteelZ01), displacement control of the corner, KrylovNewton
         (Newton does not start from the model's initial tangent). Units N, mm, MPa there
         (the Hsu-Zhong laws assume MPa).
  beam   examples/rc-beam.toml (half of a 3 m RC beam in four-point bending, Q8, bottom bars
         and stirrups) to 24 mm at the loading plate. segfem: embedded bars, the example's
         concrete (fixed cracks, IMPL-EX, crack band, MC90 plasticity from 0.3 f_cm, crush
         band). OpenSees: quad8n with ASDConcrete3D (IMPL-EX as segfem's cracks; the tension
         and compression laws sampled from segfem's, regularised by the element size), the
         plate's displacement prescribed (sp constraint, LoadControl: IMPL-EX extrapolates
         over pseudo-time, which DisplacementControl changes within a step), the bars
         as Steel01 truss elements sharing the mesh nodes (OpenSees has no embedded bars in
         2D continua), the stirrups between the nodes at y = 0.05 and 0.45 m (segfem's run
         from 0.03 to 0.47 m inside the elements).
  wall   a cantilever shear wall (2.0 m high, 1.0 m long, 0.15 m thick; boundary, web and
         horizontal bars) pushed sideways to 20 mm (about 1 % drift) through an elastic
         loading beam, on a uniform Q8 mesh of 0.05 / refine m: the RC beam's laws in both
         programs (segfem's embedded bars, OpenSees' trusses on the mesh lines), so the
         comparison is the beam's on a problem with cracking all over the web that is not
         start-up bound (issue 43 item 2). Not in the default --only.
"""

import argparse
import csv
import json
import math
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peers  # noqa: E402  (timed(), segfem_bin(), VENV_PY, WORK, CPU_TIMES)
import oofem_beam  # noqa: E402  (the OOFEM inputs)

# ---------------------------------------------------------------------------------------
# Panel PV19 (validation/panels/panels.csv)
# ---------------------------------------------------------------------------------------

PV = dict(L=0.89, t=0.07, fc=19.0e6, rx=0.0179, fyx=458e6, ry=0.0071, fyy=299e6, es=200e9)
PANEL_STOP = 0.02  # shear strain (corner ux / L) that ends the run in both programs


def write_panel(n, d, crack="rotating", tol_n=None):
    """The panel in both programs; `tol_n` [N]: the convergence test of both, the Euclidean
    norm of the unbalanced forces (segfem `absolute_force_tolerance` with the energy test
    off, OpenSees `NormUnbalance`); None: each program's own (segfem's default relative
    test, OpenSees 1e-4 t L)."""
    d.mkdir(parents=True, exist_ok=True)
    L, t = PV["L"], PV["t"]
    nodes = [f"[{L * i / n!r}, {L * j / n!r}]" for j in range(n + 1) for i in range(n + 1)]
    els = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i + 1
            els.append(f"[{a}, {a + 1}, {a + n + 2}, {a + n + 1}]")
    q = 1e6 * t  # N/m of edge shear per MPa of v (load factor = v in MPa)
    (d / "segfem.toml").write_text(
        f"""title = "PV19 panel in shear, {n} x {n} Q4"
[[materials]]
name = "c"
kind = "concrete"
fcm = {PV['fc']!r}
{'crack_model = "rotating"' + chr(10) + 'compression_reduction = "vecchio_collins_1993"' if crack == "rotating" else 'crack_model = "fixed"'}
[[materials]]
name = "sx"
kind = "rebar"
E = {PV['es']!r}
fy = {PV['fyx']!r}
[[materials]]
name = "sy"
kind = "rebar"
E = {PV['es']!r}
fy = {PV['fyy']!r}
[[regions]]
name = "p"
material = "c"
thickness = {t!r}
[mesh]
type = "explicit"
nodes = [{", ".join(nodes)}]
blocks = [{{ region = "p", element = "Q4", elements = [{", ".join(els)}] }}]
[[bar_layers]]
name = "x"
material = "sx"
region = "p"
direction = [1.0, 0.0]
ratio = {PV['rx']!r}
[[bar_layers]]
name = "y"
material = "sy"
region = "p"
direction = [0.0, 1.0]
ratio = {PV['ry']!r}
[[supports]]
name = "pin"
point = [0.0, 0.0]
ux = 0.0
uy = 0.0
[[supports]]
name = "roller"
point = [{L!r}, 0.0]
uy = 0.0
[[load_cases]]
name = "shear"
line_loads = [
  {{ line = [[0.0, {L!r}], [{L!r}, {L!r}]], q = [{q!r}, 0.0] }},
  {{ line = [[0.0, 0.0], [{L!r}, 0.0]], q = [{-q!r}, 0.0] }},
  {{ line = [[{L!r}, 0.0], [{L!r}, {L!r}]], q = [0.0, {q!r}] }},
  {{ line = [[0.0, 0.0], [0.0, {L!r}]], q = [0.0, {-q!r}] }},
]
[[monitors]]
name = "corner_ux"
kind = "displacement"
point = [{L!r}, {L!r}]
component = "x"
[[steps]]
name = "shear"
kind = "arc_length"
loads = {{ shear = 1.0 }}
initial_increment = 0.1
max_growth = 4.0
stop_displacement = {{ point = [{L!r}, {L!r}], component = "x", value = {PANEL_STOP * L!r} }}
increments = 4000
"""
        + ("" if tol_n is None else f"[solver]\nabsolute_force_tolerance = {tol_n!r}\nenergy_tolerance = 1e-30\n")
    )
    # OpenSees in N, mm, MPa: load factor = v [MPa].
    Lm, tm, fc = L * 1e3, t * 1e3, PV["fc"] / 1e6
    (d / "opensees.py").write_text(
        f"""import openseespy.opensees as ops, json, time
n, L, t, fc = {n}, {Lm!r}, {tm!r}, {fc!r}
t0 = time.perf_counter()
ops.wipe(); ops.model('basic', '-ndm', 2, '-ndf', 2)
ops.uniaxialMaterial('SteelZ01', 1, {PV['fyx'] / 1e6!r}, {PV['es'] / 1e6!r}, fc, {PV['rx']!r})
ops.uniaxialMaterial('SteelZ01', 2, {PV['fyy'] / 1e6!r}, {PV['es'] / 1e6!r}, fc, {PV['ry']!r})
ops.uniaxialMaterial('ConcreteL01', 3, -fc, -0.002)
ops.uniaxialMaterial('ConcreteL01', 4, -fc, -0.002)
ops.nDMaterial('ReinforcedConcretePlaneStress', 10, 0.0, 1, 2, 3, 4, 0.0, math.pi / 2 if False else 1.5707963267948966,
               {PV['rx']!r}, {PV['ry']!r}, fc, {PV['fyx'] / 1e6!r}, {PV['es'] / 1e6!r}, 0.002)
h = L / n
for j in range(n + 1):
    for i in range(n + 1):
        ops.node(j * (n + 1) + i + 1, i * h, j * h)
ops.fix(1, 1, 1); ops.fix(n + 1, 0, 1)
for j in range(n):
    for i in range(n):
        a = j * (n + 1) + i + 1
        ops.element('quad', j * n + i + 1, a, a + 1, a + n + 2, a + n + 1, t, 'PlaneStress', 10)
ops.timeSeries('Linear', 1); ops.pattern('Plain', 1, 1)
def edge(nodes, fx, fy):
    for k, nd in enumerate(nodes):
        w = h / 2 if k in (0, len(nodes) - 1) else h
        ops.load(nd, fx * w, fy * w)
edge([n * (n + 1) + i + 1 for i in range(n + 1)], t, 0.0)
edge([i + 1 for i in range(n + 1)], -t, 0.0)
edge([j * (n + 1) + n + 1 for j in range(n + 1)], 0.0, t)
edge([j * (n + 1) + 1 for j in range(n + 1)], 0.0, -t)
ops.system('UmfPack'); ops.numberer('RCM'); ops.constraints('Plain')
ops.test('NormUnbalance', {'1e-4 * t * L' if tol_n is None else repr(tol_n)}, 100)
ops.algorithm('KrylovNewton')
tip = (n + 1) ** 2
nsteps = 200
ops.integrator('DisplacementControl', tip, 1, {PANEL_STOP!r} * L / nsteps)
ops.analysis('Static')
t1 = time.perf_counter()
rows, iters = [], 0
for k in range(nsteps):
    ok = ops.analyze(1)
    iters += ops.testIter()
    if ok != 0:
        break
    rows.append((ops.nodeDisp(tip, 1) / L, ops.getLoadFactor(1)))
t2 = time.perf_counter()
json.dump({{'rows': rows, 'iterations': iters, 'increments': len(rows), 'completed': ok == 0,
           'setup_s': t1 - t0, 'analysis_s': t2 - t1}}, open('opensees_result.json', 'w'))
print('RESULT', max(r[1] for r in rows))
""".replace("math.pi / 2 if False else ", "")
    )
    return {"segfem": d / "segfem.toml", "OpenSees": d / "opensees.py"}


def secant_drop(rows, frac=0.9):
    """First (x, P) where the secant P/x falls below frac of the first row's: cracking."""
    k0 = rows[0][1] / rows[0][0]
    for x, p in rows:
        if x != 0 and p / x < frac * k0:
            return p
    return float("nan")


def panel_answers_segfem(out):
    rows = list(csv.DictReader(open(out / "history.csv")))
    L = PV["L"]
    xy = [(float(r["corner_ux [m]"]) / L, float(r["factor:shear [-]"])) for r in rows]
    its = sum(int(r["iterations"]) for r in rows)
    return xy, its


def panel_answers(xy):
    ipk = max(range(len(xy)), key=lambda i: xy[i][1])
    return {
        "cracking v [MPa] (secant < 0.9 initial)": secant_drop(xy),
        "peak v [MPa]": xy[ipk][1],
        "shear strain at peak [-]": xy[ipk][0],
    }


# ---------------------------------------------------------------------------------------
# RC beam: examples/rc-beam.toml and its OpenSees counterpart
# ---------------------------------------------------------------------------------------

BEAM = dict(L=1.6, Hb=0.5, Ht=0.03, E=33.55e9, nu=0.2, fcm=38e6, fy=500e6, es=200e9, et=1e9)


def beam_mesh(r):
    """The example's banded Q8 mesh refined r times: nodes, (elements, region), index."""
    nx, ny_b, ny_t = 32 * r, 10 * r, 1 * r
    L, Hb, Ht = BEAM["L"], BEAM["Hb"], BEAM["Ht"]
    xs = [L * i / (2 * nx) for i in range(2 * nx + 1)]
    ys = [Hb * j / (2 * ny_b) for j in range(2 * ny_b)] + [Hb + Ht * j / (2 * ny_t) for j in range(2 * ny_t + 1)]
    ny = ny_b + ny_t
    idx, nodes = {}, []
    for j in range(2 * ny + 1):
        for i in range(2 * nx + 1):
            if i % 2 and j % 2:
                continue
            idx[(i, j)] = len(nodes)
            nodes.append((xs[i], ys[j]))

    def inside(box, cx, cy):
        return box[0][0] <= cx <= box[1][0] and box[0][1] <= cy <= box[1][1]

    elems = []
    for j in range(0, 2 * ny, 2):
        for i in range(0, 2 * nx, 2):
            c = [(i, j), (i + 2, j), (i + 2, j + 2), (i, j + 2)]
            m = [(i + 1, j), (i + 2, j + 1), (i + 1, j + 2), (i, j + 1)]
            cx, cy = (xs[i] + xs[i + 2]) / 2, (ys[j] + ys[j + 2]) / 2
            if cy > Hb:
                reg = "plate" if inside(((1.0, 0.5), (1.2, 0.53)), cx, cy) else "void"
            elif inside(((1.0, 0.45), (1.2, 0.5)), cx, cy) or inside(((0.05, 0.0), (0.15, 0.05)), cx, cy):
                reg = "celastic"
            else:
                reg = "concrete"
            elems.append(([idx[p] for p in c + m], reg))
    return nodes, elems, idx, (nx, ny_b, ny)


def asd_laws(h):
    """segfem's concrete laws as ASDConcrete3D point lists for elements of size h [m].

    Tension: linear to f_tm, then segfem's crack-band exponential σ = f_tm exp(−(ε−ε0)/α),
    α = G_f/(h f_tm) − ε0/2, as pure damage (secant unloading). Compression: elastic to
    0.3 f_cm, the MC90 curve to (ε_c1, f_cm), then Feenstra's parabola to zero at
    ε_u = ε_c1 + 1.5 G_c/(h f_cm), as plasticity (no damage). ASDConcrete3D rescales the
    areas with its own element length (-autoRegularization h)."""
    E, fcm = BEAM["E"], BEAM["fcm"]
    ftm = 10e6 * 0.14 * (fcm / 10e6) ** (2 / 3)
    gf = 30.0 * (fcm / 10e6) ** 0.7
    gc = 250 * gf
    e0 = ftm / E
    a = gf / (h * ftm) - e0 / 2
    te = [0.0, e0] + [e0 + a * k for k in (0.25, 0.5, 1, 1.5, 2, 3, 4, 6, 8)]
    ts = [0.0, ftm] + [ftm * math.exp(-(e - e0) / a) for e in te[2:]]
    td = [0.0, 0.0] + [1 - s / (E * e) for e, s in zip(te[2:], ts[2:])]
    ec1 = 0.0022
    k = E * ec1 / fcm

    def mc90(e):
        return fcm * (k * e / ec1 - (e / ec1) ** 2) / (1 + (k - 2) * e / ec1)

    ce = [0.0, 0.3 * fcm / E] + [ec1 * f for f in (0.3, 0.5, 0.7, 0.85, 1.0)]
    cs = [0.0, 0.3 * fcm] + [mc90(e) for e in ce[2:]]
    eu = ec1 + 1.5 * gc / (h * fcm)
    for f in (0.25, 0.5, 0.75, 0.95):
        ce.append(ec1 + f * (eu - ec1))
        cs.append(max(fcm * (1 - f * f), 0.01 * fcm))
    return te, ts, td, ce, cs


def opensees_head(nodes, elems, asd_opts, h):
    """The start of an OpenSees script of the beam or the wall: the timer, the model, the nodes
    and the two concrete materials (1: ASDConcrete3D on the laws of `asd_laws(h)` with the
    options `asd_opts`, e.g. "'-implex', "; 2: elastic)."""
    te, ts, td, ce, cs = asd_laws(h)
    E, nu = BEAM["E"], BEAM["nu"]
    return f"""import openseespy.opensees as ops, json, math, time
t0 = time.perf_counter()
ops.wipe(); ops.model('basic', '-ndm', 2, '-ndf', 2)
nodes = {nodes!r}
elems = {elems!r}
for k, (x, y) in enumerate(nodes):
    ops.node(k + 1, x, y)
ops.nDMaterial('ASDConcrete3D', 1, {E!r}, {nu!r}, '-Te', *{te!r}, '-Ts', *{ts!r}, '-Td', *{td!r},
               '-Ce', *{ce!r}, '-Cs', *{cs!r}, {asd_opts}'-autoRegularization', {h!r})
ops.nDMaterial('ElasticIsotropic', 2, {E!r}, {nu!r})
"""


def opensees_stepping(tol_n, calls):
    """The end of an OpenSees script of the beam or the wall, after its load pattern and its
    `record()` (the row of a converged increment): the solver, segfem's convergence test
    (`tol_n` [N], 10 N for None), the stepping of `run(total, n)` and the result file.
    `calls` runs the steps (e.g. "run(0.0005, 25) and run(0.0195, 120)"); the pseudo-time is
    the control displacement's magnitude [m], in either direction."""
    return f"""ops.system('UmfPack'); ops.numberer('RCM'); ops.constraints('Transformation')
# The same test as segfem's with --tolerance (segfem's example: 1e-4 of its force scale).
ops.test('NormUnbalance', {10.0 if tol_n is None else tol_n!r}, 30)
ops.algorithm('Newton')
ops.analysis('Static')
t1 = time.perf_counter()
rows, iters, fails = [], 0, 0
def run(total, n):
    # segfem's increments; a failed increment is halved (up to 8 times, as segfem's
    # max_cuts) and the size regrows after each success.
    global iters, fails
    du0 = total / n
    done, du = 0.0, du0
    while abs(done) < abs(total) - 1e-12:
        du = math.copysign(min(abs(du), abs(total - done)), total)
        ops.integrator('LoadControl', abs(du))
        ok = ops.analyze(1)
        iters += ops.testIter()
        if ok != 0:
            fails += 1
            du /= 2
            if abs(du) < abs(du0) / 256:
                return False
            continue
        done += du
        ops.reactions()
        rows.append(record())
        if abs(du) < abs(du0):
            du *= 2
    return True
okk = {calls}
t2 = time.perf_counter()
json.dump({{'rows': rows, 'iterations': iters, 'failed_attempts': fails, 'completed': okk,
           'increments': len(rows), 'setup_s': t1 - t0, 'analysis_s': t2 - t1}}, open('opensees_result.json', 'w'))
print('RESULT', max(r[1] for r in rows))
"""


def write_beam(r, d, implex=True, stop_mm=24.0, tol_n=None):
    """The beam to 24 mm (the example), or only its first `stop_mm` <= 0.5 mm (the first
    step's 0.02 mm increments: elastic start and first cracking, where OOFEM gets to).
    `tol_n` [N]: the convergence test of both programs, the Euclidean norm of the unbalanced
    forces (segfem `absolute_force_tolerance` with the energy test off, OpenSees
    `NormUnbalance`); None: each program's own (the example's relative 1e-4, OpenSees 10 N)."""
    d.mkdir(parents=True, exist_ok=True)
    text = (peers.REPO / "examples" / "rc-beam.toml").read_text()
    # Same output policy as the peer (final state only), the control point's displacement
    # as a monitor, and the mesh refined r times.
    text = text.replace('output = "increments"\n', "")
    text = text.replace("nx = 32\n", f"nx = {32 * r}\n")
    text = text.replace('rows = 10 }, { region = "top_band", depth = 0.03, rows = 1 }',
                        f'rows = {10 * r} }}, {{ region = "top_band", depth = 0.03, rows = {r} }}')
    text += '\n[[monitors]]\nname = "control_uy"\nkind = "displacement"\npoint = [1.1, 0.53]\ncomponent = "y"\n'
    if stop_mm < 24.0:
        n1 = round(stop_mm / 0.02)
        assert n1 <= 25 and abs(n1 * 0.02 - stop_mm) < 1e-9, "stop_mm: a multiple of 0.02 up to 0.5"
        head, tail = text.split('[[steps]]\nname = "to_failure"')
        tail = tail[tail.index("\n[solver]"):]
        text = head.replace("value = -0.0005 }\nincrements = 25", f"value = {-stop_mm / 1e3!r} }}\nincrements = {n1}") + tail
        assert f"increments = {n1}" in text
    if tol_n is not None:
        assert "force_tolerance = 1e-4\n" in text
        text = text.replace(
            "force_tolerance = 1e-4\n",
            f"absolute_force_tolerance = {tol_n!r}\nenergy_tolerance = 1e-30\n",
        )
    (d / "segfem.toml").write_text(text)

    nodes, elems, idx, (nx, ny_b, ny) = beam_mesh(r)
    L = BEAM["L"]
    h = 0.05 / r
    bars = [idx[(i, 2 * r)] for i in range(2 * nx + 1)]
    stirrups = []
    for s in range(6):
        i = round((0.175 + 0.15 * s) * 2 * nx / L)
        stirrups.append([idx[(i, j)] for j in range(2 * r, 2 * ny_b - 2 * r + 1, 2)])
    sup = idx[(round(0.1 * 2 * nx / L), 0)]
    sym = [idx[(2 * nx, j)] for j in range(2 * ny_b + 1)]
    ctrl = idx[(round(1.1 * 2 * nx / L), 2 * ny)]
    mid = idx[(2 * nx, 0)]
    # Implicit ASDConcrete3D (-tangent: consistent tangent by perturbation) was tried first:
    # it stopped at 1.1 mm (P 59 kN, cracking, before yield) after 8 cuts.
    asd_opts = "'-implex', " if implex else "'-tangent', "
    (d / "opensees.py").write_text(
        opensees_head(nodes, elems, asd_opts, h) + f"""ops.nDMaterial('ElasticIsotropic', 3, 200e9, 0.3)
ops.nDMaterial('ElasticIsotropic', 4, 1e6, 0.0)
mats = {{'concrete': 1, 'celastic': 2, 'plate': 3, 'void': 4}}
for k, (e, reg) in enumerate(elems):
    ops.element('quad8n', k + 1, *[v + 1 for v in e], 0.3, 'PlaneStress', mats[reg])
ops.uniaxialMaterial('Steel01', 10, {BEAM['fy']!r}, {BEAM['es']!r}, {BEAM['et'] / BEAM['es']!r})
ne = len(elems)
bar = {bars!r}
bottom = []
for a, b in zip(bar[:-1], bar[1:]):
    ne += 1
    ops.element('truss', ne, a + 1, b + 1, 6.03e-4, 10)
    bottom.append(ne)
for st in {stirrups!r}:
    for a, b in zip(st[:-1], st[1:]):
        ne += 1
        ops.element('truss', ne, a + 1, b + 1, 1.0e-4, 10)
ops.fix({sup} + 1, 0, 1)
for k in {sym!r}:
    ops.fix(k + 1, 1, 0)
ops.timeSeries('Linear', 1); ops.pattern('Plain', 1, 1); ops.sp({ctrl} + 1, 2, -1.0)
def record():
    s = max(ops.eleResponse(e, 'axialForce')[0] for e in bottom) / 6.03e-4
    return (ops.nodeDisp({ctrl} + 1, 2), -ops.nodeReaction({ctrl} + 1, 2), ops.nodeDisp({mid} + 1, 2), s)
""" + opensees_stepping(tol_n, 'run(-0.0005, 25) and run(-0.0235, 120)' if stop_mm >= 24.0 else f'run({-stop_mm / 1e3!r}, {round(stop_mm / 0.02)})')
    )
    return {"segfem": d / "segfem.toml", "OpenSees": d / "opensees.py"}


def beam_answers(rows):
    """rows: (control uy [m], P [N] > 0, midspan uy [m], bottom steel max [Pa])."""
    xy = [(-u, p) for u, p, _, _ in rows]
    ipk = max(range(len(rows)), key=lambda i: rows[i][1])
    y = next((p for _, p, _, s in rows if s >= 0.999 * BEAM["fy"]), float("nan"))
    return {
        "cracking P [kN] (secant < 0.9 initial)": secant_drop(xy) / 1e3,
        "yield P [kN] (bottom bar at f_y)": y / 1e3,
        "peak P [kN]": rows[ipk][1] / 1e3,
        "P at the end [kN]": rows[-1][1] / 1e3,
        "end: plate displacement [mm]": -rows[-1][0] * 1e3,
    }


def beam_rows_segfem(out):
    rows = list(csv.DictReader(open(out / "history.csv")))
    data = [
        (float(r["control_uy [m]"]), -float(r["control_force [N]"]), float(r["midspan_uy [m]"]), float(r["steel_max [Pa]"]))
        for r in rows
    ]
    return data, sum(int(r["iterations"]) for r in rows)


# ---------------------------------------------------------------------------------------
# Cantilever shear wall (issue 43 item 2: a panel problem that is not start-up bound)
# ---------------------------------------------------------------------------------------

# Wall 2.0 m high, 1.0 m long, 0.15 m thick, on a fixed base, pushed sideways through a
# 0.2 m elastic loading beam (0.3 m thick) on top. Modelled lying down: x along the height
# (base at x = 0, beam from x = 2.0 to 2.2), y along the wall's length. Boundary bars
# 4 Ø16 (8.04 cm²) at 50 mm from each edge, web verticals 2 Ø10 (1.57 cm²) at the quarter
# points, horizontals 2 Ø8 (1.0 cm²) every 0.2 m; concrete and steel as the RC beam's.
# Section analysis: cracking near 35 kN, yield of the boundary bars near 200 kN at 7–8 mm
# (1 % drift is 21 mm): flexure with diagonal web cracking.
WALL = dict(H=2.0, top=0.2, lw=1.0, t=0.15, t_top=0.3, edge=8.04e-4, web=1.57e-4, horiz=1.0e-4)
WALL_VERTICAL_Y = (0.05, 0.25, 0.5, 0.75, 0.95)
WALL_HORIZONTAL_X = tuple(0.1 + 0.2 * k for k in range(10))
WALL_CONTROL = (2.1, 0.5)


def wall_mesh(r):
    """The wall's uniform Q8 mesh (0.05 / r elements): nodes, (elements, region), index."""
    nx, ny = 44 * r, 20 * r
    L, D = WALL["H"] + WALL["top"], WALL["lw"]
    xs = [L * i / (2 * nx) for i in range(2 * nx + 1)]
    ys = [D * j / (2 * ny) for j in range(2 * ny + 1)]
    idx, nodes = {}, []
    for j in range(2 * ny + 1):
        for i in range(2 * nx + 1):
            if i % 2 and j % 2:
                continue
            idx[(i, j)] = len(nodes)
            nodes.append((xs[i], ys[j]))
    elems = []
    for j in range(0, 2 * ny, 2):
        for i in range(0, 2 * nx, 2):
            c = [(i, j), (i + 2, j), (i + 2, j + 2), (i, j + 2)]
            m = [(i + 1, j), (i + 2, j + 1), (i + 1, j + 2), (i, j + 1)]
            reg = "top" if (xs[i] + xs[i + 2]) / 2 > WALL["H"] else "concrete"
            elems.append(([idx[p] for p in c + m], reg))
    return nodes, elems, idx, (nx, ny)


def write_wall(r, d, tol_n=None, stop_mm=20.0):
    """The wall in both programs, pushed to `stop_mm` at the loading beam's axis: 0.5 mm in
    25 increments, then the rest in 120. `tol_n` [N] as for the beam (None: each program's
    own, segfem's relative 1e-4, OpenSees 10 N)."""
    d.mkdir(parents=True, exist_ok=True)
    H, lw, t = WALL["H"], WALL["lw"], WALL["t"]
    h = 0.05 / r
    bars = []
    for k, y in enumerate(WALL_VERTICAL_Y):
        a = WALL["edge"] if k in (0, len(WALL_VERTICAL_Y) - 1) else WALL["web"]
        bars.append((f"v{k}", [[0.0, y], [H, y]], a))
    for k, x in enumerate(WALL_HORIZONTAL_X):
        bars.append((f"h{k}", [[round(x, 6), 0.05], [round(x, 6), lw - 0.05]], WALL["horiz"]))
    bar_text = "".join(
        f'\n[[bars]]\nname = "{n}"\npath = {p!r}\narea = {a!r}\nmaterial = "B500"\n' for n, p, a in bars
    )
    solver = ("force_tolerance = 1e-4\n" if tol_n is None
              else f"absolute_force_tolerance = {tol_n!r}\nenergy_tolerance = 1e-30\n")
    (d / "segfem.toml").write_text(
        f"""title = "Cantilever shear wall 2.0 x 1.0 x 0.15 m, refine {r}"
[[materials]]
name = "C30"
kind = "concrete"
fcm = {BEAM['fcm']!r}
nu = {BEAM['nu']!r}
tension_softening = "crack_band"
initial_yield_ratio = 0.3
compression_softening = "crush_band"
crack_integration = "implex"
[[materials]]
name = "B500"
kind = "rebar"
E = {BEAM['es']!r}
fy = {BEAM['fy']!r}
Et = {BEAM['et']!r}
[[materials]]
name = "C30_elastic"
kind = "elastic"
E = {BEAM['E']!r}
nu = {BEAM['nu']!r}
[[regions]]
name = "wall"
material = "C30"
thickness = {t!r}
[[regions]]
name = "top"
material = "C30_elastic"
thickness = {WALL['t_top']!r}
boxes = [[[{H!r}, 0.0], [{H + WALL['top']!r}, {lw!r}]]]
[mesh]
type = "banded"
length = {H + WALL['top']!r}
nx = {44 * r}
element = "Q8"
bands = [{{ region = "wall", depth = {lw!r}, rows = {20 * r} }}]
{bar_text}
[[supports]]
name = "base"
line = [[0.0, 0.0], [0.0, {lw!r}]]
ux = 0.0
uy = 0.0
[[monitors]]
name = "control_uy"
kind = "displacement"
point = {list(WALL_CONTROL)!r}
component = "y"
[[monitors]]
name = "steel_max"
kind = "bar_stress"
bar = "v0"
[[steps]]
name = "cracking"
kind = "displacement"
control = {{ point = {list(WALL_CONTROL)!r}, component = "y", value = 0.0005 }}
increments = 25
[[steps]]
name = "to_failure"
kind = "displacement"
control = {{ point = {list(WALL_CONTROL)!r}, component = "y", value = {stop_mm / 1e3!r} }}
increments = 120
[solver]
{solver}max_iterations = 30
max_cuts = 8
"""
    )
    nodes, elems, idx, (nx, ny) = wall_mesh(r)
    L = H + WALL["top"]
    ix = lambda x: round(x * 2 * nx / L)  # noqa: E731
    jy = lambda y: round(y * 2 * ny / lw)  # noqa: E731
    trusses = []  # (node list along the bar, area)
    for _, path, a in bars:
        (x0, y0), (x1, y1) = path
        if y0 == y1:
            line = [idx[(i, jy(y0))] for i in range(ix(x0), ix(x1) + 1)]
        else:
            line = [idx[(ix(x0), j)] for j in range(jy(y0), jy(y1) + 1)]
        trusses.append((line, a))
    base = [idx[(0, j)] for j in range(2 * ny + 1)]
    ctrl = idx[(ix(WALL_CONTROL[0]), jy(WALL_CONTROL[1]))]
    (d / "opensees.py").write_text(
        opensees_head(nodes, elems, "'-implex', ", h) + f"""mats = {{'concrete': (1, {t!r}), 'top': (2, {WALL['t_top']!r})}}
for k, (e, reg) in enumerate(elems):
    m, th = mats[reg]
    ops.element('quad8n', k + 1, *[v + 1 for v in e], th, 'PlaneStress', m)
ops.uniaxialMaterial('Steel01', 10, {BEAM['fy']!r}, {BEAM['es']!r}, {BEAM['et'] / BEAM['es']!r})
ne = len(elems)
edge = []
for n, (line, a) in enumerate({trusses!r}):
    for p, q in zip(line[:-1], line[1:]):
        ne += 1
        ops.element('truss', ne, p + 1, q + 1, a, 10)
        if n == 0:
            edge.append((ne, a))
for k in {base!r}:
    ops.fix(k + 1, 1, 1)
ops.timeSeries('Linear', 1); ops.pattern('Plain', 1, 1); ops.sp({ctrl} + 1, 2, 1.0)
def record():
    s = max(ops.eleResponse(e, 'axialForce')[0] / a for e, a in edge)
    return (ops.nodeDisp({ctrl} + 1, 2), ops.nodeReaction({ctrl} + 1, 2), s)
""" + opensees_stepping(tol_n, f'run(0.0005, 25) and run({stop_mm / 1e3 - 0.0005!r}, 120)')
    )
    return {"segfem": d / "segfem.toml", "OpenSees": d / "opensees.py"}


def wall_answers(rows):
    """rows: (control uy [m] > 0, P [N] > 0, edge bar stress max [Pa])."""
    xy = [(u, p) for u, p, _ in rows]
    ipk = max(range(len(rows)), key=lambda i: rows[i][1])
    y = next((p for _, p, s in rows if s >= 0.999 * BEAM["fy"]), float("nan"))
    return {
        "cracking P [kN] (secant < 0.9 initial)": secant_drop(xy) / 1e3,
        "yield P [kN] (edge bar at f_y)": y / 1e3,
        "peak P [kN]": rows[ipk][1] / 1e3,
        "P at the end [kN]": rows[-1][1] / 1e3,
        "end: displacement [mm]": rows[-1][0] * 1e3,
    }


def wall_rows_segfem(out):
    rows = list(csv.DictReader(open(out / "history.csv")))
    data = [
        (float(r["control_uy [m]"]), abs(float(r["control_force [N]"])), float(r["steel_max [Pa]"]))
        for r in rows
    ]
    return data, sum(int(r["iterations"]) for r in rows)


# ---------------------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------------------


def run_segfem(path, answers_of):
    out = path.parent / "segfem_out"
    # Exit status 3: the run ended where no equilibrium was found past the peak (the panel's
    # end); the results up to there are written. No field files (--no-fields): OpenSees
    # writes its rows only, segfem its history, summary and checkpoint (issue 43 item 1).
    wall, rss, _, _ = peers.timed(
        [peers.segfem_bin(), "run", "-q", "--no-fields", path.name, "-o", out.name], path.parent, ok=(0, 3)
    )
    cpu = peers.CPU_TIMES[-1]
    data, its = answers_of(out)
    return dict(wall=wall, cpu=cpu, rss=rss, iterations=its, increments=len(data), data=data)


def run_opensees(path):
    wall, rss, _, _ = peers.timed([peers.VENV_PY, path.name], path.parent)
    cpu = peers.CPU_TIMES[-1]
    res = json.loads((path.parent / "opensees_result.json").read_text())
    return dict(wall=wall, cpu=cpu, rss=rss, iterations=res["iterations"], increments=res["increments"],
                data=[tuple(r) for r in res["rows"]], completed=res["completed"])


def run_oofem(files, parse):
    """OOFEM through its Python module (bench/peers/oofem_beam.py writes the input). Its
    NRSolver here has no cut-back: a step that reaches maxiter is accepted unconverged
    (counted as `unconverged`); a material's fatal error ends the process (`completed`
    False, the steps written up to there are kept)."""
    path, info = files
    wall, rss, out, err = peers.timed([peers.VENV_PY, path.name], path.parent, ok=range(-64, 256))
    cpu = peers.CPU_TIMES[-1]
    per, unconv = oofem_beam.nr_iterations(out + err, info["maxiter"])
    rows = parse(path.parent, info)
    done = "TIMES setup" in out and info.get("done", lambda rows: True)(rows)
    return dict(wall=wall, cpu=cpu, rss=rss, iterations=sum(per), increments=len(rows), data=rows,
                completed=done, unconverged=unconv)


def bench(name, runners, rounds, answers):
    res = {p: [] for p in runners}
    for k in range(rounds):
        for p, run in runners.items():
            r = run()
            res[p].append(r)
            print(f"  {name}: {p} round {k + 1}: {r['wall']:.2f} s wall, {r['cpu']:.2f} s CPU, "
                  f"{r['increments']} increments, {r['iterations']} iterations", file=sys.stderr, flush=True)
    lines = []
    ref = answers(res["segfem"][-1]["data"])
    for p, rs in res.items():
        wall = statistics.median(r["wall"] for r in rs)
        cpu = statistics.median(r["cpu"] for r in rs)
        its = rs[-1]["iterations"]
        ans = answers(rs[-1]["data"])
        extra = "" if rs[-1].get("completed", True) else " (stopped early)"
        if rs[-1].get("unconverged"):
            extra += f" ({rs[-1]['unconverged']} steps accepted unconverged)"
        lines.append(
            f"| {name} | {p}{extra} | {wall:.2f} | {cpu:.2f} | {len(rs)} | {rs[-1]['increments']} | {its} | "
            f"{1e3 * wall / its:.1f} | {1e3 * cpu / its:.1f} | {max(r['rss'] for r in rs) / 2**20:.0f} | "
            + "; ".join(f"{k} {v:.4g} ({(v - ref[k]) / ref[k]:+.1%})" if p != "segfem" else f"{k} {v:.4g}"
                        for k, v in ans.items())
            + " |"
        )
    return lines, res


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", default="panel,beam")
    ap.add_argument(
        "--modes", default="one,all",
        help="one: every program pinned to one core with one thread (OpenBLAS too); all: every core; "
             "a table block per mode (peers.py --modes)",
    )
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--panel-n", type=int, default=1, help="panel mesh n x n Q4 (OpenSees' RCPS stops at first cracking on n > 1: a uniform panel cracks everywhere at once)")
    ap.add_argument("--panel-crack", default="rotating",
                    help="segfem's panel concrete: rotating (+ VC93 compression softening, the panel series' best) or fixed (seed beta, OOFEM's ConcreteFCM counterpart)")
    ap.add_argument("--refine", type=int, default=1, help="beam and wall mesh refinement (1 = the example; the wall's 0.05 m elements)")
    ap.add_argument("--json", default="", help="also write all runs to this file")
    ap.add_argument(
        "--compression", default="implicit",
        help="segfem's compression plasticity on the beam and the wall: implicit (its default) or implex "
             "(compression_integration = \"implex\", as OpenSees' ASDConcrete3D; docs/theory-concrete.md §4)",
    )
    ap.add_argument(
        "--tolerance", default="10",
        help="the convergence test of segfem and OpenSees, the same in both: the Euclidean norm of the "
             "unbalanced forces [N] (default 10 N, OpenSees' on the beam), or 'own' for each program's own "
             "(segfem's relative test with its energy test; OpenSees 10 N on the beam, 1e-4 t L on the panel)",
    )
    ap.add_argument("--programs", default="segfem,OpenSees,OOFEM", help="which programs (segfem always runs: the reference)")
    ap.add_argument("--oofem-law", default="fcm", help="OOFEM concrete of the beam and panel: fcm, idm1, rcsd (oofem_beam.py)")
    ap.add_argument("--oofem-beta", type=float, default=None, help="constant shear retention of OOFEM's fcm (default: segfem's law tabulated)")
    ap.add_argument("--oofem-maxiter", type=int, default=30)
    ap.add_argument("--oofem-rtolf", type=float, default=1e-3,
                    help="OOFEM's relative force tolerance (its default 1e-3; at 1e-4 its secant iterations stall at 1.5e-4 in the first cracks)")
    ap.add_argument("--stop-mm", type=float, default=24.0,
                    help="beam: plate displacement [mm] where all programs stop (24 = the example; <= 0.5: the first 0.02 mm increments)")
    args = ap.parse_args()
    table = [
        "| problem | program | wall [s] (median) | CPU [s] (median) | runs | increments | Newton iterations | wall per iteration [ms] | CPU per iteration [ms] | peak memory [MiB] | answers (difference from segfem) |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    dump = {}
    only = args.only.split(",")
    progs = args.programs.split(",")
    tol_n = None if args.tolerance == "own" else float(args.tolerance)
    if args.compression not in ("implicit", "implex"):
        sys.exit(f"--compression {args.compression}: implicit or implex")

    def compression(files):
        """segfem's input with `--compression implex` written into its concrete."""
        if args.compression == "implex":
            f = files["segfem"]
            text = f.read_text()
            assert 'crack_integration = "implex"' in text
            f.write_text(text.replace('crack_integration = "implex"',
                                      'crack_integration = "implex"\ncompression_integration = "implex"', 1))
        return files
    modes = args.modes.split(",")
    if any(m not in ("one", "all") for m in modes):
        sys.exit(f"--modes {args.modes}: each mode is one or all")
    load0 = peers.os.getloadavg()[0]
    tol_text = "each program's own test" if tol_n is None else f"both at ||unbalance||_2 <= {tol_n:g} N, no energy test"
    def each_mode(key, name, runners, answers):
        """The runs of one problem in every mode of --modes, into the table and the dump."""
        for mode in modes:
            peers.MODE = mode
            lines, res = bench(f"{name} [{mode}]", runners, args.rounds, answers)
            table.extend(lines)
            dump[f"{key} {mode}"] = res
            print("\n".join(lines), flush=True)
        peers.MODE = None

    if "panel" in only:
        files = write_panel(args.panel_n, peers.WORK / f"nl_panel_{args.panel_n}", args.panel_crack, tol_n)
        ofiles = oofem_beam.write_panel(peers.WORK / f"nl_panel_{args.panel_n}" / "oofem", args.oofem_law)
        runners = {
            "segfem": lambda: run_segfem(files["segfem"], panel_answers_segfem),
            "OpenSees": lambda: run_opensees(files["OpenSees"]),
            "OOFEM": lambda: run_oofem(ofiles, oofem_beam.parse_panel),
        }
        runners = {p: f for p, f in runners.items() if p == "segfem" or p in progs}
        name = f"PV19 panel, {args.panel_n}x{args.panel_n} Q4, {2 * (args.panel_n + 1) ** 2} dofs, {tol_text}"
        each_mode("panel", name, runners, panel_answers)
    if "beam" in only:
        files = compression(write_beam(args.refine, peers.WORK / f"nl_beam_{args.refine}", stop_mm=args.stop_mm, tol_n=tol_n))
        nodes, _, _, _ = beam_mesh(args.refine)
        ofiles = oofem_beam.write_beam(args.refine, peers.WORK / f"nl_beam_{args.refine}" / "oofem", args.oofem_law,
                                       beta=args.oofem_beta, maxiter=args.oofem_maxiter, rtolf=args.oofem_rtolf,
                                       stop_mm=args.stop_mm)
        ofiles[1]["done"] = lambda rows: bool(rows) and rows[-1][0] <= -args.stop_mm / 1e3 * (1 - 1e-6)
        runners = {
            "segfem": lambda: run_segfem(files["segfem"], beam_rows_segfem),
            "OpenSees": lambda: run_opensees(files["OpenSees"]),
            "OOFEM": lambda: run_oofem(ofiles, oofem_beam.parse_beam),
        }
        runners = {p: f for p, f in runners.items() if p == "segfem" or p in progs}
        name = f"RC beam (examples/rc-beam.toml) refine {args.refine}, Q8, {2 * len(nodes)} dofs, to {args.stop_mm} mm, {tol_text}, segfem compression {args.compression}"
        each_mode("beam", name, runners, beam_answers)
    if "wall" in only:
        files = compression(write_wall(args.refine, peers.WORK / f"nl_wall_{args.refine}", tol_n=tol_n))
        nodes, _, _, _ = wall_mesh(args.refine)
        runners = {
            "segfem": lambda: run_segfem(files["segfem"], wall_rows_segfem),
            "OpenSees": lambda: run_opensees(files["OpenSees"]),
        }
        runners = {p: f for p, f in runners.items() if p == "segfem" or p in progs}
        name = f"shear wall refine {args.refine}, Q8, {2 * len(nodes)} dofs, to 20 mm, {tol_text}, segfem compression {args.compression}"
        each_mode("wall", name, runners, wall_answers)
    print(f"\n{peers.time.strftime('%Y-%m-%d %H:%M UTC', peers.time.gmtime())}, {peers.processor()}, "
          f"load average at the start: {load0:.2f}, at the end: {peers.os.getloadavg()[0]:.2f}")
    print("\n".join(table))
    if args.json:
        Path(args.json).write_text(json.dumps(dump))


if __name__ == "__main__":
    main()
