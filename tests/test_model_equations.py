"""The model's equations are stated once (geardyn.solve._model); the benchmark's C loop spells the same
expressions.  Its text is run here as Python (IEEE doubles, no contraction: what gcc -ffp-contract=off
computes) against the compiled statement on random inputs, bit for bit, so the two cannot drift apart.
Nothing is compiled with a C compiler."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from benchmarks import kernels
from geardyn.solve import _model
from geardyn.solve.base import BACKLASH_ON, LAYOUT, B

ROOT = Path(__file__).resolve().parents[1]


def _statements(block: str, macro=None) -> list[str]:
    """C statements of ``block`` as Python lines: declarations dropped, one assignment per line, calls of
    the macro ``macro = (params, body lines)`` expanded (arguments substituted token by token)."""
    out = []
    for stmt in block.replace("{", ";").replace("}", ";").split(";"):
        stmt = re.sub(r"^\s*(const\s+)?double\s+", "", stmt.strip())
        call = re.fullmatch(r"RHS\((.*)\)", stmt)
        if call and macro is not None:
            args = dict(zip(macro[0], (f"({a.strip()})" for a in call[1].split(",")), strict=True))
            out += [re.sub(r"\b\w+\b", lambda t, args=args: args.get(t[0], t[0]), line) for line in macro[1]]
        elif stmt and "=" in stmt:
            out += [part.strip() for part in re.split(r",\s*(?=[A-Za-z_]\w*\s*=)", stmt)]
    return out


def _c_as_python():
    """The RK4 step of ``kernels.C_RK4`` as a Python function step(c, th, tk, tp, y) -> new y."""
    src = kernels.C_RK4
    fdead = src[src.index("static inline double fdead") : src.index("#define RHS")]
    py = ["def fdead(x, b, on):"]
    py += [f"    if {m[1]}: return {m[2]}" for m in re.finditer(r"if \((.*?)\) return (.*?);", fdead)]
    py.append("    return " + re.search(r"\n\s*return (.*?);\n}", fdead)[1])
    text = src[src.index("#define RHS") : src.index("void run")].replace("\\\n", " ")
    macro = (re.match(r"#define RHS\((.*?)\)", text)[1].split(", "), _statements(text[text.index("{") :]))
    loop = src[src.index("void run") :]
    consts = loop[loop.index("const double") : loop.index("for (int per")]
    step = loop[loop.index("double h = th[j]") : loop.index("x1 = n1;")]
    py.append("def step(c, th, tk, tp, y):")
    py.append("    j = 0")
    py += [f"    {line}" for line in _statements(consts) + _statements(step, macro)]
    py.append("    return n1, n2, n3, m1, m2, m3")
    namespace: dict = {}
    exec("\n".join(py), namespace)
    return namespace, py


def test_the_c_text_is_translated_whole():
    ns, lines = _c_as_python()
    assert {"fdead", "step"} <= set(ns)
    # the 4 stages: each RHS call expanded into the macro's 4 lines (fm_ and the three accelerations)
    assert kernels.C_RK4.count("RHS(") - 1 == 4
    assert sum("fm_ =" in line for line in lines) == 4
    assert sum(line.strip().startswith("(d3) =") for line in lines) == 1


@pytest.mark.parametrize("on", [1.0, 0.0])
def test_c_loop_equals_the_model_statement(on):
    step = _c_as_python()[0]["step"]
    rng = np.random.default_rng(7)
    n_in_zone = 0
    for _ in range(300):
        c = rng.uniform(0.1, 2.0, len(LAYOUT))
        c[BACKLASH_ON] = on
        b = c[B]
        y = rng.normal(0.0, 2.0, 6)
        n_in_zone += abs(y[1]) <= b
        h = rng.uniform(1e-3, 1e-1)
        k3 = rng.uniform(0.5, 1.5, 3)
        p3 = rng.normal(0.0, 0.5, 3)
        y_c = step([float(v) for v in c], [h], [float(v) for v in k3], [float(v) for v in p3], [float(v) for v in y])
        y_nb = _model.rk4(
            tuple(float(v) for v in c),
            float(b) if on else 0.0,
            h,
            *(float(v) for v in k3),
            *(float(v) for v in p3),
            *(float(v) for v in y),
        )[:6]
        assert np.array_equal(np.array(y_c), np.array(y_nb)), (c, y, h)
    assert n_in_zone > 30  # both sides of the dead zone were exercised


def test_importing_the_benchmarks_changes_no_environment_variable(tmp_path):
    """Every benchmark module imports without setting an environment variable or compiling the C loop
    (only ``python -m benchmarks.bench`` pins the thread pools; the C RK4 is built when its mode runs).
    geardyn's own process settings (its import sets them: geardyn.libm) are in place before."""
    mods = ", ".join(f"benchmarks.{p.stem}" for p in sorted((ROOT / "benchmarks").glob("*.py")) if p.stem != "__init__")
    code = (
        f"import geardyn, os; before = dict(os.environ); import {mods}; "
        "assert dict(os.environ) == before, set(os.environ.items()) ^ set(before.items())"
    )
    env = {k: v for k, v in os.environ.items() if not k.endswith("_NUM_THREADS")}
    env["TMPDIR"] = str(tmp_path)
    subprocess.run([sys.executable, "-c", code], check=True, env=env, cwd=ROOT)
    assert not any(tmp_path.rglob("*.so"))
