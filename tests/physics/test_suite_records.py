"""The shipped synthetic suite (records/suite, scripts/make_suite.py) reads and is current."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from helpers import load_script

from rocksweep.physics.intensity import velocity
from rocksweep.physics.records import at2_text, read_record

ROOT = Path(__file__).resolve().parents[2]
SUITE = ROOT / "records" / "suite"


def test_every_suite_file_parses():
    files = sorted(SUITE.glob("*.AT2"))
    assert [f.name for f in files] == [f"SYN{i:02d}.AT2" for i in range(1, 21)]
    for f in files:
        rec = read_record(f)
        assert rec.dt == 0.01
        assert 20.0 <= rec.duration <= 40.0
        assert 0.02 < rec.pga < 2.0
        # the high-pass post-filter brings the ground nearly to rest
        v = velocity(rec.acc, rec.dt)
        assert abs(v[-1]) < 0.1 * np.max(np.abs(v))
        assert "Rezaeian" in rec.title


@pytest.mark.parametrize("index", [0, 13])
def test_suite_files_match_the_generator(index):
    mod = load_script("make_suite")
    acc, dt, title = mod.suite_record(index)
    path = SUITE / f"SYN{index + 1:02d}.AT2"
    assert path.read_text("ascii") == at2_text(acc, dt, title)


def test_envelope_hits_its_arias_targets():
    mod = load_script("make_suite")
    ia, d595, tmid = 0.1, 15.0, 9.0
    a1, a2, a3 = mod.envelope_params(ia, d595, tmid)
    t = np.arange(0.0, 200.0, 0.001)
    q2 = mod.envelope(t, a1, a2, a3) ** 2
    cum = np.cumsum(q2) * 0.001
    assert math.pi / 2 * cum[-1] == pytest.approx(ia, rel=1e-3)
    frac = cum / cum[-1]
    t05, t45, t95 = (t[np.searchsorted(frac, p)] for p in (0.05, 0.45, 0.95))
    assert t95 - t05 == pytest.approx(d595, abs=0.01)
    assert t45 - mod.T0 == pytest.approx(tmid, abs=0.01)
