"""IDA per record (rocksweep.ida, rocksweep fragility --rtol): the first overturning level
of each record of a scaled suite, bisected between stripes."""

from __future__ import annotations

import dataclasses
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from bodies import FIG3_YAML
from click.testing import CliRunner

import rocksweep
from rocksweep.cli import main
from rocksweep.compute.single import run_point
from rocksweep.kernel import layout as L  # noqa: N812
from rocksweep.physics.bodies import G
from rocksweep.scene.inputs import load

ROOT = Path(__file__).resolve().parents[2]
NAMES = ["SYN01.AT2", "SYN05.AT2", "SYN12.AT2"]
SCENE = """
name: ida test
""" + FIG3_YAML + """impact: {lam: 0.0}
ground:
  records: suite/*.AT2
  scale: {im: PGA, values: [0.2, 0.4, 0.6, 0.8, 1.2, 1.6]}
  p: 2.0
"""


@pytest.fixture(scope="module")
def suite(tmp_path_factory):
    d = tmp_path_factory.mktemp("ida")
    (d / "suite").mkdir()
    for n in NAMES:
        shutil.copy(ROOT / "records" / "suite" / n, d / "suite" / n)
    (d / "s.yaml").write_text(SCENE)
    out = d / "s.h5"
    ds = rocksweep.run(d / "s.yaml", output=out)
    return d, ds, out


def test_bisected_level_brackets_the_first_overturning(suite):
    d, ds, _ = suite
    rtol = 1e-3
    r = rocksweep.ida(ds, rtol=rtol)
    assert r.ida_im.dims == ("record",)
    levels = ds.PGA.values
    over = np.isin(ds.outcome.transpose("record", "PGA").values, (1, 2))
    sc = load(d / "s.yaml")[0]
    checked = 0
    for k, name in enumerate(ds.record.values):
        if not over[k].any():
            assert np.isnan(float(r.ida_im.sel(record=name)))
            continue
        j = int(over[k].argmax())
        hi, lo = float(r.ida_hi.sel(record=name)), float(r.ida_lo.sel(record=name))
        est = float(r.ida_im.sel(record=name))
        assert hi <= levels[j]
        if j == 0:
            assert np.isnan(lo) and int(r.upper_bound.sel(record=name)) == 1 and est == hi
            continue
        assert levels[j - 1] <= lo < est < hi and hi - lo <= rtol * hi
        assert est == pytest.approx(math.sqrt(lo * hi), rel=1e-12)  # not a copy of hi
        # independently: the scaled record's peak acceleration is the IM level (PGA [g]),
        # and single runs at the sweep's numerics overturn at hi and not at lo
        top = sc.point({"record": name, "PGA": levels[j], "lam": 0.0, "p": 2.0,
                        **{a.name: a.values[0] for a in sc.axes
                           if a.name not in ("record", "PGA", "lam", "p")}})
        for x, overturns in ((hi, True), (lo, False)):
            pt = dataclasses.replace(top, A_ratio=top.A_ratio * x / levels[j])
            assert pt.A == pytest.approx(x * G, rel=1e-12)
            out = run_point(pt, sc.numerics, history=False).out
            assert (out[L.OUT_OUTCOME] in (1, 2)) is overturns
        checked += 1
    assert checked >= 1  # at least one record is bisected between two stripes


def test_cli_fragility_rtol_and_bad_input(suite):
    d, ds, out = suite
    res = CliRunner().invoke(main, ["fragility", str(out), "--rtol", "1e-2", "--bootstrap",
                                    "0", "-o", str(d / "f.h5")])
    assert res.exit_code == 0, res.output
    assert "IDA per record" in res.output
    import xarray as xr

    with xr.open_dataset(d / "f.h5") as f:
        assert f.ida_im.dims == ("lam", "record") or f.ida_im.dims == ("record",)
    with pytest.raises(rocksweep.RocksweepError, match="rtol"):
        rocksweep.ida(ds, rtol=2.0)
    plain = rocksweep.run(ROOT / "configs" / "ci-small.yaml",
                          overrides={"pulse.shape": "sine", "impact.lam": 0.0})
    with pytest.raises(rocksweep.RocksweepError, match="scaled record suite"):
        rocksweep.ida(plain)
