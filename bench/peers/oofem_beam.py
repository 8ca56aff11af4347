#!/usr/bin/env python3
"""OOFEM counterparts of the problems of bench/peers/nonlinear.py (issue 21 item 1).

beam  examples/rc-beam.toml: the same Q8 mesh (`qplanestress2d`, nip 9 = segfem's 3 x 3),
      IsoLE for the elastic regions, the bars and stirrups as `truss2d` elements with
      `MisesMat` (linear hardening as segfem's E_t) on the mesh nodes (as in the OpenSees
      model). Control (write_beam's docstring): arc length on the plate node's u_y with
      restarts (default; Python drives the steps and stops at the plate displacement of
      the other programs or when the run stalls), or the displacement prescribed (direct).
      The concrete is one of (--oofem-law of nonlinear.py):
        fcm   ConcreteFCM (OOFEM's fixed orthogonal cracks), exponential softening with
              segfem's f_tm and G_f, shear retention beta(w) tabulated from segfem's
              Cervenka law beta = 1 - (eps/0.005)^0.075 with w = h eps (sheartype 3), or
              a constant beta (sheartype 1).
        idm1  isotropic damage, smooth Rankine equivalent strain (tension only drives
              damage), exponential cohesive softening with G_f (crack band of the element).
        rcsd  rotating crack with scalar damage (RCM2/RCSD), linear softening with G_f.
        cdpm2 ConcreteDPM2 (damage-plasticity, yield from 0.3 f_cm as segfem's).
      Only cdpm2 has compression nonlinearity. Every one stalls at 0.38-0.42 mm, at the
      first flexural cracks (docs/performance.md, "Nonlinear side by side with OOFEM").
panel PV19 (nonlinear.py): one `planestress2d` Q4 of the panel, the smeared steel as
      `truss2d` bars along the element's edges (each edge bar half of rho t L: under the
      panel's uniform strain they strain as the smeared steel would), the edge shear as
      nodal forces, arc length with displacement control of the corner (CALM, hpc).

OOFEM's NRSolver in this wheel (2.6.0.dev1) has no cut-back: a step that does not converge
in maxiter iterations is accepted as it is (the run counts and reports such steps); its
arc length (CALM) restarts a failed step with a quarter of its length. A material's local
failure (OOFEM_ERROR) ends the process.

    python3 bench/peers/oofem_beam.py beam 1 fcm && cd bench/peers/work/oofem_beam_1_fcm && \\
        ../../.venv/bin/python run.py
"""
import math
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import nonlinear as nl  # noqa: E402
import peers  # noqa: E402

RUN_PY = """import oofem, time
t0 = time.perf_counter()
dr = oofem.OOFEMTXTDataReader('{inp}')
pb = oofem.InstanciateProblem(dr, oofem.problemMode.processor, 0, None, False)
pb.checkProblemConsistency(); pb.setRenumberFlag()
t1 = time.perf_counter()
pb.solveYourself(); pb.terminateAnalysis()
t2 = time.perf_counter()
print('TIMES setup', t1 - t0, 'analysis', t2 - t1)
print('RESULT 0')
"""


# The beam under arc length: OOFEM's own step loop (EngngModel::solveYourself) driven from
# Python so that the run stops where segfem's does, at the plate displacement `stop`.
RUN_STEPS_PY = """import oofem, time
t0 = time.perf_counter()
dr = oofem.OOFEMTXTDataReader('{inp}')
pb = oofem.InstanciateProblem(dr, oofem.problemMode.processor, 0, None, False)
pb.checkProblemConsistency(); pb.setRenumberFlag()
t1 = time.perf_counter()
dof = pb.giveDomain(1).giveDofManager({node}).giveDofWithID(oofem.DofIDItem.D_v)
done = False
hist = []
for ims in range(1, {nmsteps} + 1):
    ms = pb.giveMetaStep(ims)
    pb.initMetaStepAttributes(ms)
    dl = {dls!r}[ims - 1]
    for j in range(ms.giveNumberOfSteps()):
        pb.preInitializeNextStep()
        ts = pb.giveNextStep()
        if ts.giveNumber() == 1:
            pb.forceEquationNumbering()
        pb.initializeYourself(ts)
        pb.solveYourselfAt(ts)
        pb.updateYourself(ts)
        pb.terminate(ts)
        u = dof.giveUnknown(oofem.ValueModeType.VM_Total, ts)
        hist.append(u)
        if u <= {stop!r}:
            done = True
            break
        # Stalled: 20 steps that together moved the plate less than one step length of
        # the metastep (arc-length restarts down to tiny steps, no way past).
        if len(hist) > 20 and hist[-21] - u < dl:
            print('STALLED at', u, flush=True)
            done = True
            break
    if done:
        break
pb.terminateAnalysis()
t2 = time.perf_counter()
print('TIMES setup', t1 - t0, 'analysis', t2 - t1)
print('RESULT 0')
"""


def concrete_record(law, h, beta=None):
    E, nu, fcm = nl.BEAM["E"], nl.BEAM["nu"], nl.BEAM["fcm"]
    ftm = 10e6 * 0.14 * (fcm / 10e6) ** (2 / 3)
    gf = 30.0 * (fcm / 10e6) ** 0.7
    base = f"d 0. talpha 0. E {E!r} n {nu!r}"
    if law == "fcm":
        if beta is not None:
            shear = f"sheartype 1 beta {beta!r}"
        else:
            # segfem's default retention (src/materials/concrete, ShearRetention::default):
            # beta = 1 - (eps/0.005)^0.075, floored at 1e-3; OOFEM's table is in the largest
            # crack opening reached, w = h eps.
            eps = [0.0, 1e-7, 1e-6, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 5e-3, 1e-1]
            b = [1.0] + [max(1 - (e / 0.005) ** 0.075, 1e-3) for e in eps[1:]]
            w = [h * e for e in eps]
            shear = (f"sheartype 3 beta_w {len(w)} " + " ".join(f"{v:.6g}" for v in w)
                     + f" beta(w) {len(b)} " + " ".join(f"{v:.6g}" for v in b))
        return f"concretefcm 1 {base} Gf {gf!r} ft {ftm!r} softtype 1 {shear} ncracks 2 multiplecrackshear"
    if law == "idm1":
        return f"idm1 1 {base} e0 {ftm / E!r} gf {gf!r} equivstraintype 1 damlaw 0"
    if law == "rcsd":
        return f"rcsd 1 {base} Gf {gf!r} ft {ftm!r} sdtransitioncoeff 0.5"
    if law == "cdpm2":
        # ConcreteDPM2 (Grassl et al. 2013; input name con2dpm), 3D damage-plasticity, plane
        # stress by OOFEM's iteration on the 3D law: yield from kinit = 0.3 f_cm (segfem's
        # initial_yield_ratio), exponential tension softening sigma = f_t exp(-w/w_f) with
        # w_f = G_f/f_t (the same G_f), crack band of the element.
        return f"con2dpm 1 {base} fc {fcm!r} ft {ftm!r} wf {gf / ftm!r} stype 2 kinit 0.3"
    raise ValueError(law)


def write_beam(r, d, law="fcm", beta=None, maxiter=30, stiffmode=1, rtolf=1e-3, control="calm", restarts=8, stop_mm=24.0):
    """Write d/beam.in and d/run.py; return (run.py, info for parse_beam).

    control "direct": the plate node's displacement prescribed by a time function
    (NonLinearStatic controlmode 1, NRSolver: no cut-back, unconverged steps accepted).
    control "calm": a unit force on the plate node scaled by the load level, whose
    increments are found by OOFEM's arc length (CylindricalALM) constrained to that node's
    u_y alone (hpc): displacement control with the example's increments as the step
    lengths of two metasteps (25 x 0.02 mm, 120 x 0.19583 mm), and CALM's restart of a
    step that fails (iteration limit or NaN) with a quarter of its length, which then
    regrows toward the metastep's length (reqiterations 1000: by (1000/iterations)^(1/4) a
    step). Full Newton (manrmsteps 1), the secant matrix (stiffmode 1: ConcreteFCM's
    tangent gave NaN, idm1's stagnated)."""
    d.mkdir(parents=True, exist_ok=True)
    nodes, elems, idx, (nx, ny_b, ny) = nl.beam_mesh(r)
    L = nl.BEAM["L"]
    bars = [idx[(i, 2 * r)] for i in range(2 * nx + 1)]
    stirrups = []
    for s in range(6):
        i = round((0.175 + 0.15 * s) * 2 * nx / L)
        stirrups.append([idx[(i, j)] for j in range(2 * r, 2 * ny_b - 2 * r + 1, 2)])
    sup = idx[(round(0.1 * 2 * nx / L), 0)]
    sym = set(idx[(2 * nx, j)] for j in range(2 * ny_b + 1))
    ctrl = idx[(round(1.1 * 2 * nx / L), 2 * ny)]
    mid = idx[(2 * nx, 0)]
    E, nu = nl.BEAM["E"], nl.BEAM["nu"]
    es, et = nl.BEAM["es"], nl.BEAM["et"]
    truss = [(a, b, 6.03e-4) for a, b in zip(bars[:-1], bars[1:])]
    bottom = list(range(len(elems) + 1, len(elems) + len(truss) + 1))
    for st in stirrups:
        truss += [(a, b, 1.0e-4) for a, b in zip(st[:-1], st[1:])]
    mats = {"concrete": 1, "celastic": 2, "plate": 3, "void": 4}
    out = ["beam.out\nRC beam, examples/rc-beam.toml, OOFEM\n"]
    if control == "direct":
        out.append(f"NonLinearStatic nsteps 145 deltaT 1. rtolf {rtolf!r} maxiter {maxiter} controlmode 1 "
                   f"stiffmode {stiffmode} nmodules 0\n")
    else:
        out.append("NonLinearStatic nmsteps 2 nsteps 145 nmodules 0\n")
        # The second metastep's step count is a cap: run.py stops at 24 mm.
        for n, dl in ((25, 0.0005 / 25), (1000, 0.0235 / 120)):
            out.append(f"nsteps {n} controlmode 0 stiffmode {stiffmode} rtolf {rtolf!r} rtold 1.0 maxiter {maxiter} "
                       f"maxrestarts {restarts} reqiterations 1000 steplength {dl!r} minsteplength {dl / 4 ** restarts!r} "
                       f"psi 0. hpcmode 1 hpc 2 {ctrl + 1} 2 manrmsteps 1 donotfixload\n")
    out.append("domain 2dPlaneStress\n")
    out.append(f"OutputManager tstep_all dofman_output {{{ctrl + 1} {mid + 1}}} "
               f"element_output {{{' '.join(str(e) for e in bottom)}}}\n")
    out.append(f"ndofman {len(nodes)} nelem {len(elems) + len(truss)} ncrosssect 6 nmat 5 nbc 3 nic 0 nltf 2\n")
    for k, (x, y) in enumerate(nodes):
        bc = [0, 0]
        if k == sup:
            bc[1] = 1
        if k in sym:
            bc[0] = 1
        if k == ctrl and control == "direct":
            bc[1] = 2
        tail = f" bc 2 {bc[0]} {bc[1]}" if any(bc) else ""
        if k == ctrl and control != "direct":
            tail += " load 1 3"
        out.append(f"node {k + 1} coords 3 {x!r} {y!r} 0.0{tail}\n")
    for k, (e, reg) in enumerate(elems):
        out.append(f"qplanestress2d {k + 1} nodes 8 " + " ".join(str(v + 1) for v in e)
                   + f" nip 9 crossSect {mats[reg]} mat {mats[reg]}\n")
    for j, (a, b, A) in enumerate(truss):
        out.append(f"truss2d {len(elems) + j + 1} nodes 2 {a + 1} {b + 1} crossSect {5 if A > 2e-4 else 6} mat 5 cs 1\n")
    for c in range(1, 5):
        out.append(f"SimpleCS {c} thick 0.3 width 1.0\n")
    out.append("SimpleCS 5 area 6.03e-4\nSimpleCS 6 area 1.0e-4\n")
    out.append(concrete_record(law, 0.05 / r, beta) + "\n")
    out.append(f"IsoLE 2 d 0. E {E!r} n {nu!r} tAlpha 0.\n")
    out.append("IsoLE 3 d 0. E 200e9 n 0.3 tAlpha 0.\nIsoLE 4 d 0. E 1e6 n 0.0 tAlpha 0.\n")
    # Linear hardening H with E_t = E H / (E + H) = segfem's Et.
    out.append(f"MisesMat 5 d 0. E {es!r} n 0.3 tAlpha 0. sig0 {nl.BEAM['fy']!r} H {es * et / (es - et)!r} "
               "omega_crit 0 a 0\n")
    out.append("BoundaryCondition 1 loadTimeFunction 1 prescribedvalue 0.\n")
    out.append("BoundaryCondition 2 loadTimeFunction 2 prescribedvalue 1.\n")
    out.append("NodalLoad 3 loadTimeFunction 1 components 2 0. -1.0\n")
    out.append("ConstantFunction 1 f(t) 1.0\n")
    out.append("PiecewiseLinFunction 2 npoints 3 t 3 0. 25. 145. f(t) 3 0. -0.0005 -0.024\n")
    (d / "beam.in").write_text("".join(out))
    if control == "direct":
        (d / "run.py").write_text(RUN_PY.format(inp="beam.in"))
    else:
        (d / "run.py").write_text(RUN_STEPS_PY.format(inp="beam.in", node=ctrl + 1, nmsteps=2, stop=-stop_mm / 1e3 * (1 - 1e-9),
                                                        dls=[0.0005 / 25, 0.0235 / 120]))
    return d / "run.py", dict(ctrl=ctrl + 1, mid=mid + 1, bottom=bottom, out="beam.out", maxiter=maxiter, control=control)


def nr_iterations(log, maxiter):
    """(iterations per step, steps accepted unconverged) from OOFEM's log.

    NRSolver: lines 'NRSolver: <nite> ...' (one per convergence check; nite = solves so
    far); a step that reached maxiter is accepted as it is. CALM (arc length): one line
    'CALMLS: <i> ...' per iteration, restarted attempts included (their iterations were
    done too); a step still unconverged after its restarts is reported by a warning."""
    if "CALMLS:" in log:
        n = len(re.findall(r"^CALMLS:\s+\d+\s", log, re.M))
        steps = re.split(r"^Solving\s+\[step number", log, flags=re.M)[1:]
        per = [len(re.findall(r"^CALMLS:\s+\d+\s", st, re.M)) for st in steps]
        assert sum(per) == n
        return per, len(re.findall(r"Convergence not reached after", log))
    per, cur = [], None
    for m in re.finditer(r"^NRSolver: (\d+)\s", log, re.M):
        n = int(m.group(1))
        if n == 0 and cur is not None:
            per.append(cur)
        cur = n
    if cur is not None:
        per.append(cur)
    return per, sum(1 for n in per if n >= maxiter)


def parse_steps(text):
    """Split an OOFEM output file into its per-step blocks."""
    parts = re.split(r"^Output for time\s+", text, flags=re.M)
    return parts[1:]


def parse_beam(d, info):
    """rows (control uy [m], P [N] > 0, midspan uy [m], bottom steel max [Pa]) per step."""
    p = d / info["out"]
    if not p.exists():
        return []
    rows = []
    for blk in parse_steps(p.read_text()):
        def disp(node):
            m = re.search(rf"^Node\s+{node}\s+\(\s*{node}\):\s*\n\s*dof 1\s+d\s+(\S+)\s*\n\s*dof 2\s+d\s+(\S+)", blk, re.M)
            return float(m.group(2)) if m else float("nan")

        if info.get("control") == "direct":
            m = re.search(rf"Node\s+{info['ctrl']}\s+iDof\s+2\s+reaction\s+(\S+)", blk)
            if not m:
                continue
            react = float(m.group(1))
        else:  # the load level times the unit reference force
            m = re.search(r"Reached load level :\s*(\S+)", blk)
            if not m:
                continue
            react = -float(m.group(1))
        s = [float(v) for v in re.findall(r"stresses\s+(\S+)", blk)]
        rows.append((disp(info["ctrl"]), -react, disp(info["mid"]), max(s) if s else float("nan")))
    return rows


# ---------------------------------------------------------------------------------------
# PV19 panel
# ---------------------------------------------------------------------------------------


def write_panel(d, law="fcm", steps=200, stiffmode=1):
    """One Q4 of PV19 under the edge shear of nonlinear.write_panel, arc length (CALM)
    controlled by the corner's u_x (hpc), to a shear strain of nonlinear.PANEL_STOP."""
    d.mkdir(parents=True, exist_ok=True)
    PV = nl.PV
    L, t = PV["L"], PV["t"]
    fc = PV["fc"]
    # MC90 as segfem's `concrete` with only fcm given (src/materials/concrete/mc90):
    # E_ci = 21.5 GPa (fcm/10 MPa)^(1/3) = 26.6 GPa, f_tm = 1.4 MPa (fcm/10 MPa)^(2/3)
    # = 2.15 MPa, G_f = 30 N/m (fcm/10 MPa)^0.7 (d_max 16 mm).
    E = 21.5e9 * (fc / 10e6) ** (1 / 3)
    ftm = 1.4e6 * (fc / 10e6) ** (2 / 3)
    # segfem's panel uses the Hinton tension-stiffening law sigma = f_tm exp(-(eps - eps0)/alpha),
    # alpha = 5e-4, not a crack band (one 0.89 m element would snap back with G_f: OOFEM
    # warns and drops the softening). OOFEM's laws are in crack opening w = h eps_cr with h
    # its crack-band length across the 45-degree crack, L sqrt(2): the same decay strain is
    # G_f = alpha h f_tm for the exponential law (FCM) and the same energy for RCSD's linear.
    h = L * math.sqrt(2.0)
    gf = 5e-4 * h * ftm
    q = 1e6 * t  # N/m of edge shear per MPa of v
    F = q * L / 2  # nodal force per corner node and edge
    if law == "fcm":
        eps = [0.0, 1e-7, 1e-6, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 3e-3, 5e-3, 1e-1]
        b = [1.0] + [max(1 - (e / 0.005) ** 0.075, 1e-3) for e in eps[1:]]
        w = [h * e for e in eps]
        shear = (f"sheartype 3 beta_w {len(w)} " + " ".join(f"{v:.6g}" for v in w)
                 + f" beta(w) {len(b)} " + " ".join(f"{v:.6g}" for v in b))
        conc = f"concretefcm 1 d 0. talpha 0. E {E!r} n 0.2 Gf {gf!r} ft {ftm!r} softtype 1 {shear} ncracks 2 multiplecrackshear"
    elif law == "rcsd":
        conc = f"rcsd 1 d 0. talpha 0. E {E!r} n 0.2 Gf {gf!r} ft {ftm!r} sdtransitioncoeff 0.5"
    elif law == "cdpm2":
        conc = f"con2dpm 1 d 0. talpha 0. E {E!r} n 0.2 fc {fc!r} ft {ftm!r} wf {gf / ftm!r} stype 2 kinit 0.3"
    else:
        conc = f"idm1 1 d 0. talpha 0. E {E!r} n 0.2 e0 {ftm / E!r} gf {gf!r} equivstraintype 1 damlaw 0"
    ax, ay = PV["rx"] * t * L / 2, PV["ry"] * t * L / 2
    dl = nl.PANEL_STOP / steps * L  # corner u_x per arc-length step (OpenSees: 200 steps)
    # Reference load v = 1 MPa (load level = v in MPa): the edge shear q L per edge, half
    # to each end node. Node 1 (0, 0) pinned, node 2 (L, 0) on a roller in y; node 2 gets
    # -F x (bottom edge) and +F y (right edge), node 3 +F x +F y, node 4 +F x -F y.
    text = f"""panel.out
PV19 panel, one Q4, OOFEM
NonLinearStatic nsteps {steps} controlmode 0 stiffmode {stiffmode} rtolv 1e-4 maxiter 60 maxrestarts 8 steplength {dl!r} minsteplength {dl / 4 ** 8!r} reqiterations 1000 psi 0. hpcmode 1 hpc 2 3 1 manrmsteps 1 nmodules 0
domain 2dPlaneStress
OutputManager tstep_all dofman_output {{3}} element_output {{1 2 4}}
ndofman 4 nelem 5 ncrosssect 3 nmat 3 nbc 5 nic 0 nltf 1 nset 7
node 1 coords 3 0. 0. 0.
node 2 coords 3 {L!r} 0. 0.
node 3 coords 3 {L!r} {L!r} 0.
node 4 coords 3 0. {L!r} 0.
planestress2d 1 nodes 4 1 2 3 4
truss2d 2 nodes 2 1 2 cs 1
truss2d 3 nodes 2 4 3 cs 1
truss2d 4 nodes 2 2 3 cs 1
truss2d 5 nodes 2 1 4 cs 1
SimpleCS 1 thick {t!r} width 1.0 material 1 set 1
SimpleCS 2 area {ax!r} material 2 set 2
SimpleCS 3 area {ay!r} material 3 set 3
{conc}
MisesMat 2 d 0. E {PV['es']!r} n 0.3 tAlpha 0. sig0 {PV['fyx']!r} H 0. omega_crit 0 a 0
MisesMat 3 d 0. E {PV['es']!r} n 0.3 tAlpha 0. sig0 {PV['fyy']!r} H 0. omega_crit 0 a 0
BoundaryCondition 1 loadTimeFunction 1 dofs 2 1 2 values 2 0. 0. set 4
BoundaryCondition 2 loadTimeFunction 1 dofs 1 2 values 1 0. set 5
NodalLoad 3 loadTimeFunction 1 dofs 2 1 2 Components 2 {-F!r} {F!r} set 5
NodalLoad 4 loadTimeFunction 1 dofs 2 1 2 Components 2 {F!r} {F!r} set 6
NodalLoad 5 loadTimeFunction 1 dofs 2 1 2 Components 2 {F!r} {-F!r} set 7
ConstantFunction 1 f(t) 1.0
Set 1 elementranges {{1}}
Set 2 elementranges {{(2 3)}}
Set 3 elementranges {{(4 5)}}
Set 4 nodes 1 1
Set 5 nodes 1 2
Set 6 nodes 1 3
Set 7 nodes 1 4
"""
    (d / "panel.in").write_text(text)
    (d / "run.py").write_text(RUN_PY.format(inp="panel.in"))
    return d / "run.py", dict(out="panel.out", L=L, maxiter=60)


def parse_panel(d, info):
    """(shear strain, v [MPa]) per step: corner u_x / L and the load level."""
    p = d / info["out"]
    if not p.exists():
        return []
    rows = []
    for blk in parse_steps(p.read_text()):
        m = re.search(r"^Node\s+3\s+\(\s*3\):\s*\n\s*dof 1\s+d\s+(\S+)", blk, re.M)
        lam = re.search(r"[Ll]oad level\s*:?\s*(\S+)", blk)
        if m and lam:
            rows.append((float(m.group(1)) / info["L"], float(lam.group(1))))
    return rows


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "beam"
    if what == "beam":
        r = int(sys.argv[2]) if len(sys.argv) > 2 else 1
        law = sys.argv[3] if len(sys.argv) > 3 else "fcm"
        print(write_beam(r, peers.WORK / f"oofem_beam_{r}_{law}", law))
    else:
        law = sys.argv[2] if len(sys.argv) > 2 else "fcm"
        print(write_panel(peers.WORK / f"oofem_panel_{law}", law))
