#!/usr/bin/env python3
"""OOFEM counterpart of the RC beam of bench/peers/nonlinear.py (unfinished, issue 21 item 1).

Writes bench/peers/work/oofem_beam_R/beam.in and run.py: the same Q8 mesh (qplanestress2d),
ConcreteFCM (OOFEM's fixed-crack model) for the concrete, IsoLE for the elastic regions,
the bars and stirrups as truss2d elements with MisesMat on the mesh nodes (as in the
OpenSees model), the plate's displacement prescribed through a piecewise-linear time
function (direct displacement control, 25 + 120 steps). Run:

    python3 bench/peers/oofem_beam.py 1 && cd bench/peers/work/oofem_beam_1 && ../../.venv/bin/python run.py

State (docs/performance.md, "Not done"): elastic and first cracking agree with segfem; the
fixed-crack model's local iteration diverges in the first step of the second stage
(step 31). Not part of the timed comparison.
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import nonlinear as nl  # noqa: E402
import peers  # noqa: E402

r = int(sys.argv[1]) if len(sys.argv) > 1 else 1
d = peers.WORK / f"oofem_beam_{r}"
d.mkdir(parents=True, exist_ok=True)
nodes, elems, idx, (nx, ny_b, ny) = nl.beam_mesh(r)
L = nl.BEAM['L']
bars = [idx[(i, 2 * r)] for i in range(2 * nx + 1)]
stirrups = []
for s in range(6):
    i = round((0.175 + 0.15 * s) * 2 * nx / L)
    stirrups.append([idx[(i, j)] for j in range(2 * r, 2 * ny_b - 2 * r + 1, 2)])
sup = idx[(round(0.1 * 2 * nx / L), 0)]
sym = set(idx[(2 * nx, j)] for j in range(2 * ny_b + 1))
ctrl = idx[(round(1.1 * 2 * nx / L), 2 * ny)]
mid = idx[(2 * nx, 0)]
E, nu, fcm = nl.BEAM['E'], nl.BEAM['nu'], nl.BEAM['fcm']
ftm = 10e6 * 0.14 * (fcm / 10e6) ** (2 / 3)
gf = 30.0 * (fcm / 10e6) ** 0.7
truss = [(a, b, 6.03e-4) for a, b in zip(bars[:-1], bars[1:])]
for st in stirrups:
    truss += [(a, b, 1.0e-4) for a, b in zip(st[:-1], st[1:])]
mats = {'concrete': 1, 'celastic': 2, 'plate': 3, 'void': 4}
out = []
out.append('beam.out\nRC beam, examples/rc-beam.toml, OOFEM\n')
out.append('NonLinearStatic nsteps 145 deltaT 1. rtolf 1e-4 maxiter 30 controllmode 1 stiffmode 1 nmodules 0\n')
out.append('domain 2dPlaneStress\n')
out.append(f'OutputManager tstep_all dofman_output {{{ctrl + 1} {mid + 1}}}\n')
out.append(f'ndofman {len(nodes)} nelem {len(elems) + len(truss)} ncrosssect 6 nmat 5 nbc 2 nic 0 nltf 2\n')
for k, (x, y) in enumerate(nodes):
    bc = [0, 0]
    if k == sup: bc[1] = 1
    if k in sym: bc[0] = 1
    if k == ctrl: bc[1] = 2
    tail = f' bc 2 {bc[0]} {bc[1]}' if any(bc) else ''
    out.append(f'node {k + 1} coords 3 {x!r} {y!r} 0.0{tail}\n')
for k, (e, reg) in enumerate(elems):
    out.append(f'qplanestress2d {k + 1} nodes 8 ' + ' '.join(str(v + 1) for v in e) + f' crossSect {mats[reg]} mat {mats[reg]}\n')
for j, (a, b, A) in enumerate(truss):
    out.append(f'truss2d {len(elems) + j + 1} nodes 2 {a + 1} {b + 1} crossSect {5 if A > 2e-4 else 6} mat 5 cs 1\n')
for c in range(1, 5):
    out.append(f'SimpleCS {c} thick 0.3 width 1.0\n')
out.append('SimpleCS 5 area 6.03e-4\nSimpleCS 6 area 1.0e-4\n')
out.append(f'concretefcm 1 d 0. talpha 0. E {E!r} n {nu!r} Gf {gf!r} ft {ftm!r} softtype 1 sheartype 1 beta 0.1 multiplecrackshear\n')
out.append(f'IsoLE 2 d 0. E {E!r} n {nu!r} tAlpha 0.\n')
out.append('IsoLE 3 d 0. E 200e9 n 0.3 tAlpha 0.\nIsoLE 4 d 0. E 1e6 n 0.0 tAlpha 0.\n')
out.append(f'MisesMat 5 d 0. E 200e9 n 0.3 tAlpha 0. sig0 500e6 H {200e9 * 1e9 / (200e9 - 1e9)!r} omega_crit 0 a 0\n')
out.append('BoundaryCondition 1 loadTimeFunction 1 prescribedvalue 0.\n')
out.append('BoundaryCondition 2 loadTimeFunction 2 prescribedvalue 1.\n')
out.append('ConstantFunction 1 f(t) 1.0\n')
out.append('PiecewiseLinFunction 2 npoints 3 t 3 0. 25. 145. f(t) 3 0. -0.0005 -0.024\n')
open(d / 'beam.in', 'w').write(''.join(out))
open(d / 'run.py', 'w').write(f'''import oofem, re, json, time
t0 = time.perf_counter()
dr = oofem.OOFEMTXTDataReader('beam.in')
pb = oofem.InstanciateProblem(dr, oofem.problemMode.processor, 0, None, False)
pb.checkProblemConsistency(); pb.setRenumberFlag()
t1 = time.perf_counter()
pb.solveYourself(); pb.terminateAnalysis()
t2 = time.perf_counter()
txt = open('beam.out').read()
P = [-float(v) for v in re.findall(r'Node\\s+{ctrl + 1} iDof\\s+2 reaction\\s+(\\S+)', txt)]
print('RESULT', max(P))
json.dump({{'P': P, 'setup_s': t1 - t0, 'analysis_s': t2 - t1}}, open('oofem_result.json', 'w'))
''')
print(len(nodes), len(elems), len(truss), ctrl, mid)
