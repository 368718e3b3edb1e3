"""scripts/bench_kernel.py runs end to end in its tiny mode and prints every figure.

No timing is asserted (speed is the script's to print, not a test's to judge); the test
checks that each section is printed with a finite number in each of its cells, and that
the roofline's inlined loop is a real RK4 loop over the kernel's right-hand side (it
agrees with the kernel's own ``rk4_step``).
"""

import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "bench_kernel.py"


@pytest.fixture(scope="module")
def bench():
    sys.path.insert(0, str(SCRIPT.parent))
    try:
        import bench_kernel
    finally:
        sys.path.remove(str(SCRIPT.parent))
    return bench_kernel


def _numbers(line: str) -> list[float]:
    return [float(x) for x in re.findall(r"-?\d+\.?\d*(?:e[-+]?\d+)?", line)]


def test_tiny_run_prints_every_section():
    res = subprocess.run([sys.executable, str(SCRIPT), "--tiny"], capture_output=True,
                         text=True, timeout=600)
    assert res.returncode == 0, res.stderr
    out = res.stdout
    for head in ("[1] roofline", "[2] kernel", "[2b] event root finders", "[3] reference",
                 "[4] parallel efficiency", "[5] the four figures", "[6] warm start"):
        assert head in out, f"missing section {head!r}:\n{out}"
    lines = out.splitlines()
    # [1]: two loops per scene, four positive ns/step figures each
    roof = [ln for ln in lines if re.match(r"fig\w+\s+(inlined|rk4_step)\s", ln)]
    assert len(roof) == 4
    for ln in roof:
        ns = _numbers(ln.split(maxsplit=2)[2])
        assert len(ns) == 4 and all(v > 0 for v in ns), ln
    # [2] .. [4]: one table row per scene (and per jobs value in [4]), all cells finite
    start = {h: next(i for i, ln in enumerate(lines) if ln.startswith(h))
             for h in ("[2]", "[2b]", "[3]", "[4]", "[5]")}
    rows2 = [ln for ln in lines[start["[2]"]:start["[2b]"]] if re.match(r"fig\w+\s+\d", ln)]
    rows2b = [ln for ln in lines[start["[2b]"]:start["[3]"]] if re.match(r"fig\w+\s+[a-z]", ln)]
    rows3 = [ln for ln in lines[start["[3]"]:start["[4]"]] if re.match(r"fig\w+\s+\d", ln)]
    rows4 = [ln for ln in lines[start["[4]"]:start["[5]"]] if re.match(r"fig\w+\s+\d", ln)]
    # [4]: the grid sizes (the scene's and --eff-n: one size in --tiny) x jobs 1, 2 per scene
    assert len(rows2) == 2 and len(rows3) == 2 and len(rows4) == 4
    # [2b]: three root finders per scene, bisection's speed-up over itself is 1
    assert [ln.split()[1] for ln in rows2b] == ["bisection", "illinois", "hermite"] * 2
    assert all(_numbers(ln)[-2] == 1.0 for ln in rows2b if " bisection " in ln)
    for ln in rows2 + rows2b + rows3 + rows4:
        nums = _numbers(ln.split(maxsplit=1)[1])
        assert nums and all(math.isfinite(v) for v in nums), ln
    # [2]: 6 x 6 x 3 lam = 108 points per scene; [5]: four figures, 4 x 4 x 3 lam each
    assert all(_numbers(ln.split(maxsplit=1)[1])[0] == 108 for ln in rows2)
    total = next(ln for ln in lines if ln.startswith("total"))
    assert _numbers(total)[0] == 4 * 48


def test_inlined_roofline_is_the_kernels_rk4(bench):
    """The roofline loop integrates the same equations as the kernel's ``rk4_step``."""
    from rocksweep.scene.grid import Grid

    prm = Grid(bench.scene_of("fig3a", 4)).rows(0, 1).rows[0]
    y0 = (0.01, -0.02, 1e-3, 0.0, 0.0, 0.0)
    for s, loop in ((1, bench._bare_rocking), (0, bench._bare_contact)):
        for on in (True, False):
            a = loop(prm, y0, 0.05, 2, 40, s, on)
            b = bench._bare_kernel_step(prm, y0, 0.05, 2, 40, s, on)
            if s == 0:  # the kernel's sum also holds theta and theta', frozen in contact
                b -= 2 * (y0[0] + y0[1])
            np.testing.assert_allclose(a, b, rtol=1e-12)
