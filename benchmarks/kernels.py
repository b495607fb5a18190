"""The kernels' cost per point-step against a scalar C RK4 compiled with gcc when the mode runs, and DOP853
against the batch RK4."""

from __future__ import annotations

import ctypes
import functools
import subprocess
import tempfile
from pathlib import Path

import numba
import numpy as np

from benchmarks.common import timed
from benchmarks.work_precision import cases, interp_time
from geardyn.khv.model import static_deflection
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.base import Lane
from geardyn.solve.reference import simulate_reference
from geardyn.solve.run import simulate_batch, step_tables

C_RK4 = r"""
#include <math.h>
/* Plain RK4 of the 3-DOF backlash model on the aligned step grid, the expressions of
   geardyn.solve._model.rk4 (kappa and TE tabulated per step at the 3 stage times); a test runs this
   text as Python against that function, bit for bit (tests/test_model_equations.py). */
static inline double fdead(double x, double b, double on) {
    if (on == 0.0) return x;
    if (x > b) return x - b;
    if (x < -b) return x + b;
    return 0.0;
}
#define RHS(X1, X2, X3, V1, V2, V3, KAP, PE, A1, A2, A3) { \
    double fm_ = (KAP) * fdead((X2), B, ON) + CM * (V2); \
    A1 = P1 - K11 * (X1) - C11 * (V1) - G1 * fm_; \
    A2 = (PE) - K21 * (X1) - C21 * (V1) - K23 * (X3) - C23 * (V3) - fm_; \
    A3 = P3 - K33 * (X3) - C33 * (V3) - G3 * fm_; }
void run(const double *c, const double *th, const double *tk, const double *tp, int n, int periods, double *y) {
    const double K11 = c[0], C11 = c[1], G1 = c[2], P1 = c[3], K21 = c[4], C21 = c[5], K23 = c[6], C23 = c[7];
    const double K33 = c[8], C33 = c[9], G3 = c[10], P3 = c[11], CM = c[12], B = c[13], ON = c[17];
    double x1 = y[0], x2 = y[1], x3 = y[2], v1 = y[3], v2 = y[4], v3 = y[5];
    for (int per = 0; per < periods; per++) {
        for (int j = 0; j < n; j++) {
            double h = th[j], hh = 0.5 * h;
            double k0 = tk[3 * j], k1 = tk[3 * j + 1], k2 = tk[3 * j + 2];
            double p0 = tp[3 * j], p1 = tp[3 * j + 1], p2 = tp[3 * j + 2];
            double a1, a2, a3, b1, b2, b3, c1, c2, c3, d1, d2, d3;
            RHS(x1, x2, x3, v1, v2, v3, k0, p0, a1, a2, a3);
            double X1 = x1 + hh * v1, X2 = x2 + hh * v2, X3 = x3 + hh * v3;
            double V1 = v1 + hh * a1, V2 = v2 + hh * a2, V3 = v3 + hh * a3;
            RHS(X1, X2, X3, V1, V2, V3, k1, p1, b1, b2, b3);
            double sx1 = v1 + 2.0 * V1, sx2 = v2 + 2.0 * V2, sx3 = v3 + 2.0 * V3;
            double sv1 = a1 + 2.0 * b1, sv2 = a2 + 2.0 * b2, sv3 = a3 + 2.0 * b3;
            double W1 = v1 + hh * b1, W2 = v2 + hh * b2, W3 = v3 + hh * b3;
            RHS(x1 + hh * V1, x2 + hh * V2, x3 + hh * V3, W1, W2, W3, k1, p1, c1, c2, c3);
            sx1 += 2.0 * W1; sx2 += 2.0 * W2; sx3 += 2.0 * W3;
            sv1 += 2.0 * c1; sv2 += 2.0 * c2; sv3 += 2.0 * c3;
            double U1 = v1 + h * c1, U2 = v2 + h * c2, U3 = v3 + h * c3;
            RHS(x1 + h * W1, x2 + h * W2, x3 + h * W3, U1, U2, U3, k2, p2, d1, d2, d3);
            double h6 = h / 6.0;
            double n1 = x1 + h6 * (sx1 + U1), n2 = x2 + h6 * (sx2 + U2), n3 = x3 + h6 * (sx3 + U3);
            double m1 = v1 + h6 * (sv1 + d1), m2 = v2 + h6 * (sv2 + d2), m3 = v3 + h6 * (sv3 + d3);
            x1 = n1; x2 = n2; x3 = n3; v1 = m1; v2 = m2; v3 = m3;
        }
    }
    y[0] = x1; y[1] = x2; y[2] = x3; y[3] = v1; y[4] = v2; y[5] = v3;
}
"""

C_FLAGS = ("-O3", "-march=native", "-ffp-contract=off", "-fno-fast-math")


def compile_c_rk4(tmp: Path):
    """Compile :data:`C_RK4` with gcc into ``tmp`` (a temporary directory) and load it (ctypes)."""

    src = tmp / "rk4.c"
    lib = tmp / "rk4.so"
    src.write_text(C_RK4)
    subprocess.run(["gcc", *C_FLAGS, "-shared", "-fPIC", str(src), "-o", str(lib), "-lm"], check=True)
    so = ctypes.CDLL(str(lib))
    dp = ctypes.POINTER(ctypes.c_double)
    so.run.argtypes = [dp, dp, dp, dp, ctypes.c_int, ctypes.c_int, dp]
    so.run.restype = None

    def run_c(c, th, tk, tp, periods, y0):
        y = np.array(y0, dtype=float)
        arrs = [np.ascontiguousarray(a, dtype=float) for a in (c, th, tk, tp)]
        so.run(*(a.ctypes.data_as(dp) for a in arrs), len(th), int(periods), y.ctypes.data_as(dp))
        return y

    return run_c


def kernel_costs(lanes: int = 64, periods: int = 100, steps: int = 512, log=print) -> dict:
    """Cost per point-step: scalar C RK4 (gcc, this run), the scalar numba kernel (one point) and
    the batch kernel (lockstep lanes; one thread and all threads), plain RK4 and event RK4."""

    base = cases()["periodic"]
    systems = [base.replace(b=float(b)) for b in np.linspace(0.5, 2.5, lanes)]
    out: dict = {"lanes": lanes, "periods": periods, "steps": steps, "threads": numba.get_num_threads()}
    n_steps = lanes * periods * steps
    with tempfile.TemporaryDirectory() as tmp:
        run_c = compile_c_rk4(Path(tmp))
        tabs = [step_tables(c, steps, True) for c in systems]
        y0s = [c.static_state() for c in systems]

        def c_all():
            return [run_c(t[0], t[1], t[4], t[5], periods, y) for t, y in zip(tabs, y0s, strict=True)]

        t_c, yc = timed(c_all, 3)
    out["c_ns"] = t_c / n_steps * 1e9
    for integ in ("rk4", "rk4_event"):
        s = SimulationSettings(
            integrator=integ, steps_per_period=steps, transient_periods=periods - 1, recorded_periods=1
        )
        simulate(systems[0], s)
        simulate_batch([Lane(c) for c in systems[:9]], s)
        t_s, rs = timed(lambda s=s: [simulate(c, s) for c in systems], 3)
        nthreads = numba.get_num_threads()
        numba.set_num_threads(1)
        t_b1, _ = timed(functools.partial(simulate_batch, [Lane(c) for c in systems], s), 3)
        numba.set_num_threads(nthreads)
        t_b, rb = timed(functools.partial(simulate_batch, [Lane(c) for c in systems], s), 3)
        same = all(np.array_equal(a.final_state, b.final_state) for a, b in zip(rs, rb, strict=True))
        out[integ] = {
            "scalar_ns": t_s / n_steps * 1e9,
            "batch1_ns": t_b1 / n_steps * 1e9,
            "batch_ns": t_b / n_steps * 1e9,
            "bit_identical": same,
        }
        if integ == "rk4":
            out["c_equals_numba"] = all(np.array_equal(a, r.final_state) for a, r in zip(yc, rs, strict=True))
        log(
            f"[kernel] {integ}: C {out['c_ns']:.1f} ns/step, numba scalar {out[integ]['scalar_ns']:.1f}, "
            f"batch 1 thread {out[integ]['batch1_ns']:.1f}, batch {nthreads} threads {out[integ]['batch_ns']:.1f} "
            f"ns per point-step (bit-identical: {same})"
        )
    return out


def dop853_ratios(quick: bool = False, log=print) -> dict:
    """Speed against DOP853 at equal Poincare error (periodic case, 500 + 100 periods): wall time of the
    fixed-step RK4 (previous: one point; batch: per point of a 64-point batch) interpolated to the
    errors 1e-6 and 1e-8, against DOP853 (no step limit) at rtol 1e-6, 1e-8, 1e-10."""

    c = cases()["periodic"]
    ntr, nrec = (50, 10) if quick else (500, 100)
    y0 = static_deflection(c)
    ref = simulate(
        c, SimulationSettings(integrator="dop853", transient_periods=ntr, recorded_periods=nrec, rtol=1e-12), y0
    )
    steps = (128, 256, 512, 1024)
    lanes = 64
    err, t_old, t_new = [], [], []
    for n in steps:
        s = SimulationSettings(steps_per_period=n, transient_periods=ntr, recorded_periods=nrec)
        simulate_batch([Lane(c)] * 9, s)
        to, r = timed(functools.partial(simulate, c, s, y0), 3)
        tn, rb = timed(functools.partial(simulate_batch, [Lane(c, y0)] * lanes, s), 2)
        assert np.array_equal(rb[0].poincare, r.poincare)
        err.append(float(np.abs(r.poincare - ref.poincare).max()))
        t_old.append(to)
        t_new.append(tn / lanes)
        log(
            f"[dop853] N={n}: error {err[-1]:.2e}, previous {to * 1e3:.1f} ms/point, "
            f"batch {tn / lanes * 1e3:.2f} ms/point"
        )
    dt, de = [], []
    for rt in (1e-6, 1e-8, 1e-10):
        s = SimulationSettings(integrator="dop853", transient_periods=ntr, recorded_periods=nrec, rtol=rt)
        t, r = timed(functools.partial(simulate_reference, c, s, y0, max_step_fraction=np.inf), 1)
        dt.append(t)
        de.append(float(np.abs(r.poincare - ref.poincare).max()))
        log(f"[dop853] rtol {rt:.0e}: {t:.2f} s, error {de[-1]:.2e}")
    out = {"steps": steps, "error": err, "t_old": t_old, "t_new": t_new, "dop_time": dt, "dop_error": de}
    for target in (1e-6, 1e-8):
        t_dp = interp_time(np.array(de), np.array(dt), target)
        for key, tt in (("old", t_old), ("new", t_new)):
            t_rk = interp_time(np.array(err), np.array(tt), target)
            out[f"ratio_{key}_{target:.0e}"] = t_dp / t_rk if np.isfinite(t_rk * t_dp) else float("nan")
    return out
