"""Ground-motion records: the AT2 / two-column parser, its one-line errors, the writer and
the two shipped records (documented NPTS, DT, PGA, sha256; the sine record against the
closed-form sine; the near-fault record ends at rest and matches its generator)."""

from __future__ import annotations

import hashlib
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from rocksweep.errors import OutputError, RecordError, RocksweepError
from rocksweep.physics.excitation import PulseShape
from rocksweep.physics.records import (
    GroundRecord,
    at2_text,
    fortran_e,
    kernel_series,
    parse_record,
    read_record,
    write_at2,
)

ROOT = Path(__file__).resolve().parents[2]
RECORDS = ROOT / "records"

NGA_HEAD = ("PEER NGA STRONG MOTION DATABASE RECORD\n"
            "Imperial Valley-06, 10/15/1979, Station X, 140\n"
            "ACCELERATION TIME SERIES IN UNITS OF G\n")
OLD_HEAD = ("PACIFIC ENGINEERING AND ANALYSIS STRONG-MOTION DATA\n"
            " IMPERIAL VALLEY 10/15/79 2316, STATION X, 230\n"
            " ACCELERATION TIME HISTORY IN UNITS OF G\n")
# 12 values, five per line, a partial last line of two
VALUES = [0.001, -0.002, 0.0035, 0.25, -0.5, 0.125, 0.0, 1e-5, -3e-4, 0.0625, 0.03125, -0.75]
DATA = ("  .1000000E-02  -.2000000E-02   .3500000E-02   .2500000E+00  -.5000000E+00\n"
        "  .1250000E+00   .0000000E+00   .1000000E-04  -.3000000E-03   .6250000E-01\n"
        "  .3125000E-01  -.7500000E+00\n")


def _write(tmp_path: Path, name: str, text: str | bytes) -> Path:
    path = tmp_path / name
    path.write_bytes(text.encode("latin-1") if isinstance(text, str) else text)
    return path


def _error(path: Path) -> str:
    with pytest.raises(RecordError) as err:
        read_record(path)
    msg = str(err.value)
    assert "\n" not in msg
    assert isinstance(err.value, RocksweepError)
    return msg


# --- reading -------------------------------------------------------------------------

def test_nga_west2_header_and_partial_last_line(tmp_path):
    text = NGA_HEAD + "NPTS=    12, DT=   .0100 SEC\n" + DATA
    path = _write(tmp_path, "rsn1_station.AT2", text)
    rec = read_record(path)
    assert isinstance(rec, GroundRecord)
    assert (rec.name, rec.npts, rec.dt) == ("rsn1_station", 12, 0.01)
    np.testing.assert_array_equal(rec.acc, VALUES)  # the partial last line is kept
    assert rec.acc.dtype == np.float64 and not rec.acc.flags.writeable
    assert rec.pga == 0.75
    assert rec.sha256 == hashlib.sha256(text.encode()).hexdigest()
    assert rec.source == str(path)
    assert rec.title == "Imperial Valley-06, 10/15/1979, Station X, 140"
    assert rec.duration == pytest.approx(0.11)


@pytest.mark.parametrize("line4", ["  12    0.01000   NPTS, DT", "12 .0100 NPTS, DT",
                                   "   12    .01000E+00   NPTS, DT, SEC"])
def test_older_peer_header_gives_the_numbers_first(tmp_path, line4):
    rec = read_record(_write(tmp_path, "old.at2", OLD_HEAD + line4 + "\n" + DATA))
    assert (rec.npts, rec.dt) == (12, 0.01)
    np.testing.assert_array_equal(rec.acc, VALUES)


def test_dt_is_read_to_full_precision(tmp_path):
    # a reader that rounds DT to three decimals would read 0.0001 as 0 and .0025 as .003
    for dt_text, dt in ((".0001", 1e-4), (".0025", 0.0025), ("0.00390625", 0.00390625)):
        rec = parse_record((NGA_HEAD + f"NPTS=    12, DT= {dt_text} SEC\n" + DATA).encode(),
                           "x.AT2")
        assert rec.dt == dt


def test_crlf_line_ends_read_the_same(tmp_path):
    text = NGA_HEAD + "NPTS=    12, DT=   .0100 SEC\n" + DATA
    lf = read_record(_write(tmp_path, "lf.AT2", text))
    crlf = read_record(_write(tmp_path, "crlf.AT2", text.replace("\n", "\r\n")))
    np.testing.assert_array_equal(crlf.acc, lf.acc)
    assert (crlf.dt, crlf.npts, crlf.title) == (lf.dt, lf.npts, lf.title)
    assert crlf.sha256 != lf.sha256  # the hash is of the bytes


def test_fortran_style_numbers(tmp_path):
    data = (".1234E-02 -.5E-03 1.0D-02 2.5d+00 -7\n"
            "-.1234E-02-.5678E-03 +.25E1  3.  0.0\n")
    rec = read_record(_write(tmp_path, "f.AT2", NGA_HEAD + "NPTS=10, DT=.02 SEC\n" + data))
    assert rec.acc.tolist() == [0.001234, -0.0005, 0.01, 2.5, -7.0,
                                -0.001234, -0.0005678, 2.5, 3.0, 0.0]


def test_two_column_files(tmp_path):
    ws = "# t [s]  acc [g]\n0.00  0.0\n0.01  0.5\n0.02 -0.25\n\n0.03  1e-2\n"
    comma = "# time,acc\n0.00,0.0\n0.01, 0.5\n0.02,-0.25\n0.03,1E-02\r\n"
    for name, text in (("a.txt", ws), ("b.csv", comma)):
        rec = read_record(_write(tmp_path, name, text))
        assert (rec.npts, rec.title) == (4, "")
        assert rec.dt == pytest.approx(0.01, rel=1e-12)
        assert rec.acc.tolist() == [0.0, 0.5, -0.25, 0.01]
        assert rec.pga == 0.5
    # printed (rounded) times are accepted; the first row is t = 0
    thirds = "".join(f"{0.5 + i / 3:.4f} {math.sin(i):.6f}\n" for i in range(30))
    rec = read_record(_write(tmp_path, "thirds.dat", thirds))
    assert rec.dt == pytest.approx(1 / 3, rel=1e-4)
    assert rec.times()[0] == 0.0 and rec.npts == 30


# --- malformed files: one line naming the file and the line --------------------------

def test_missing_header(tmp_path):
    path = _write(tmp_path, "x.AT2", DATA + DATA)
    assert _error(path) == (f"{path}, line 4: missing header: expected 'NPTS=  4000, DT= "
                            ".01000 SEC' or '4000  0.0100  NPTS, DT', found "
                            "'.1000000E-02  -.2000000E-02...'")
    short = _write(tmp_path, "short.AT2", NGA_HEAD[:-1])
    assert _error(short) == f"{short}, line 3: file ends inside the 4-line AT2 header"


def test_npts_not_matching_the_values(tmp_path):
    more = _write(tmp_path, "more.AT2", NGA_HEAD + "NPTS=    13, DT=   .0100 SEC\n" + DATA)
    assert _error(more) == (f"{more}, line 7: the file ends after 12 values, but NPTS = 13 "
                            "(line 4)")
    fewer = _write(tmp_path, "fewer.AT2", NGA_HEAD + "NPTS=    11, DT=   .0100 SEC\n" + DATA)
    assert _error(fewer) == f"{fewer}, line 7: value 12 is past NPTS = 11 (line 4)"
    head_only = _write(tmp_path, "head.AT2", NGA_HEAD + "NPTS=  4000, DT= .01000 SEC\n\n")
    assert _error(head_only) == (f"{head_only}, line 4: the file ends after 0 values, but "
                                 "NPTS = 4000 (line 4)")


@pytest.mark.parametrize("line4, msg", [
    ("NPTS=     1, DT=   .0100 SEC", "NPTS = '1': must be an integer >= 2"),
    ("NPTS=  12.5, DT=   .0100 SEC", "NPTS = '12.5': must be an integer >= 2"),
    ("NPTS=    12, DT=   .0000 SEC", "DT = '.0000': must be > 0 [s]"),
    ("NPTS=    12, DT=  -.0100 SEC", "DT = '-.0100': must be > 0 [s]"),
    ("NPTS=    12, DT=   NaN SEC", "value 'NaN' is not finite"),
])
def test_bad_npts_or_dt(tmp_path, line4, msg):
    path = _write(tmp_path, "h.AT2", NGA_HEAD + line4 + "\n" + DATA)
    assert _error(path) == f"{path}, line 4: {msg}"


@pytest.mark.parametrize("bad, msg", [
    ("NaN", "value 'NaN' is not finite"),
    ("-inf", "value '-inf' is not finite"),
    ("1.0E+999", "value '1.0E+999' is not finite"),
    ("abc", "'abc' is not a number"),
    ("1.2.3", "'1.2.3' is not a number"),
])
def test_non_finite_or_non_numeric_values(tmp_path, bad, msg):
    data = DATA.replace(".1250000E+00", bad)
    assert data != DATA
    path = _write(tmp_path, "v.AT2", NGA_HEAD + "NPTS=    12, DT=   .0100 SEC\n" + data)
    assert _error(path) == f"{path}, line 6: {msg}"


def test_empty_velocity_and_motionless_files(tmp_path):
    for text in ("", "  \n\n"):
        path = _write(tmp_path, "empty.AT2", text)
        assert _error(path) == f"{path}: empty file"
    vel = NGA_HEAD.replace("ACCELERATION TIME SERIES IN UNITS OF G",
                           "VELOCITY TIME SERIES IN UNITS OF CM/S")
    path = _write(tmp_path, "x.VT2", vel + "NPTS=    12, DT=   .0100 SEC\n" + DATA)
    assert _error(path) == (f"{path}, line 3: 'VELOCITY TIME SERIES IN UNITS OF CM/S': not an "
                            "acceleration record in units of g")
    zeros = _write(tmp_path, "z.AT2", NGA_HEAD + "NPTS= 3, DT= .01 SEC\n 0. 0. .0E+00\n")
    assert _error(zeros) == f"{zeros}: every value is 0 (PGA = 0): no motion to scale"


def test_unreadable_paths(tmp_path):
    missing = tmp_path / "nope.AT2"
    assert _error(missing) == f"{missing}: no such record file"
    assert _error(tmp_path) == f"{tmp_path}: is a directory, not a record file"


@pytest.mark.parametrize("text, line, msg", [
    ("0.0 0.1\n0.01 0.2\n0.01 0.3\n", 3, "time 0.01 s is not after 0.01 s: times must increase"),
    ("0.0 0.1\n0.02 0.2\n0.01 0.3\n", 3, "time 0.01 s is not after 0.02 s: times must increase"),
    ("0.0 0.1\n0.01 0.2\n0.03 0.3\n0.04 0.1\n", 3,
     "time step 0.02 s differs from the first step 0.01 s (line 2): times must be uniformly "
     "spaced"),
    ("# t a\n0.0 0.1 7\n", 2, "expected 2 columns (t [s], xg'' [g]), found 3; a header line "
     "must start with #"),
    ("time acc\n0.0 0.1\n", 1, "'time' is not a number"),
    ("0.0 0.1\n0.01 nan\n", 2, "value 'nan' is not finite"),
    ("# only one\n0.0 0.1\n", 2, "1 sample(s): a record needs at least 2"),
])
def test_malformed_two_column_files(tmp_path, text, line, msg):
    path = _write(tmp_path, "r.txt", text)
    assert _error(path) == f"{path}, line {line}: {msg}"


# --- interpolation, kernel time, writer ----------------------------------------------

def test_linear_interpolation_and_rest_after_the_last_sample(tmp_path):
    rec = parse_record((NGA_HEAD + "NPTS=    12, DT=   .0100 SEC\n" + DATA).encode(), "x.AT2")
    assert rec.acc_at(0.035) == pytest.approx(0.5 * (0.25 - 0.5))  # samples 3 and 4
    assert rec.acc_at(0.11) == pytest.approx(-0.75)  # the last sample is still on
    assert rec.acc_at(0.11 + 1e-9) == 0.0
    assert rec.acc_at(-1e-9) == 0.0
    dt_k, shape = kernel_series(rec, p=2.5)
    assert dt_k == pytest.approx(0.025)
    np.testing.assert_allclose(shape, np.array(VALUES) / 0.75)
    assert shape.flags.c_contiguous and shape.dtype == np.float64
    with pytest.raises(RecordError, match=r"p = 0.0: must be a finite number > 0"):
        kernel_series(rec, 0.0)


@pytest.mark.parametrize("x, text", [(0.0012345678, "  .1234568E-02"),
                                     (-0.75, "  -.7500000E+00"), (0.0, "   .0000000E+00"),
                                     (9.99999999, "   .1000000E+02"), (1e-20, "   .1000000E-19")])
def test_fortran_e_is_e15_7(x, text):
    assert fortran_e(x) == text.rjust(15) and len(fortran_e(x)) == 15


def test_writer_round_trip_and_output_policy(tmp_path):
    rng = np.random.default_rng(3)
    acc = rng.normal(scale=0.2, size=13)
    path = write_at2(tmp_path / "w.AT2", acc, 0.0025, "title line")
    rec = read_record(path)
    assert (rec.npts, rec.dt, rec.title) == (13, 0.0025, "title line")
    np.testing.assert_allclose(rec.acc, acc, rtol=5.1e-7)  # 7 digits, mantissa >= .1
    lines = path.read_text().splitlines()
    assert lines[3] == "NPTS=    13, DT=   .0025 SEC"
    assert [len(x.split()) for x in lines[4:]] == [5, 5, 3]
    with pytest.raises(OutputError, match="already exists"):
        write_at2(path, acc, 0.0025, "again")
    write_at2(path, acc[:4], 0.0025, "again", overwrite=True)
    assert read_record(path).npts == 4


# --- the shipped records ---------------------------------------------------------------

# documented in the README (records section) and in scripts/make_records.py
SHIPPED = {
    "sine_1cycle.AT2": (5001, 1e-4, 1.0,
                        "d6c6f4e5c9cd7ebcfd07a445499324e2b59079633c46b4fc8fbd910b7954e25e"),
    "synthetic_nearfault.AT2": (5001, 0.005, 0.4481875,
                                "8d6be6372f2f87551d53c46431709e1d7fdce742e05e911ff4f0e905107e258f"),
}


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_records_have_the_documented_npts_dt_pga(name):
    npts, dt, pga, sha = SHIPPED[name]
    path = RECORDS / name
    rec = read_record(path)
    assert (rec.npts, rec.dt, rec.pga, rec.sha256) == (npts, dt, pga, sha)
    assert path.stat().st_size < 500_000


def test_sine_record_is_the_one_cycle_sine_pulse():
    """T = 0.5 s, 1 g: linear interpolation is within (w DT)^2/8 = 2e-7 of sin(w t), plus
    5e-8 of printing, at any time, and equals the `sine` pulse shape of rocksweep.physics.excitation
    (w = 2 pi / T), including rest after the pulse."""
    rec = read_record(RECORDS / "sine_1cycle.AT2")
    w = 2 * math.pi / 0.5
    t = np.random.default_rng(11).uniform(0.0, 0.5, 20_000)
    np.testing.assert_allclose(rec.acc_at(t), np.sin(w * t), rtol=0, atol=2.6e-7)
    t = np.linspace(-0.1, 0.7, 8001)
    np.testing.assert_allclose(rec.acc_at(t), PulseShape("sine").acc(w * t), rtol=0, atol=2.6e-7)
    assert rec.duration == pytest.approx(0.5, rel=1e-15)


def test_nearfault_record_ends_at_rest_with_its_pulse_in_the_velocity():
    """Zero net velocity (trapezoid rule on the samples) and the peak ground velocity in
    the MP pulse's window 4 s <= t <= 4 + gamma T_p = 7.52 s, close to its 0.80 m/s."""
    rec = read_record(RECORDS / "synthetic_nearfault.AT2")
    g = 9.81
    t = rec.times()
    v = np.concatenate([[0.0], np.cumsum(0.5 * (rec.acc[1:] + rec.acc[:-1]) * rec.dt)]) * g
    pgv = np.abs(v).max()
    assert abs(v[-1]) < 1e-4 * pgv
    assert 4.0 <= t[np.argmax(np.abs(v))] <= 7.52
    assert 0.6 * 0.80 <= pgv <= 1.1 * 0.80
    assert 20.0 <= rec.duration <= 30.0
    assert abs(rec.acc[0]) < 1e-12 and abs(rec.acc[-1]) < 1e-12  # tapered ends


def test_shipped_records_match_their_generator():
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import make_records
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    for name, make in make_records.FILES.items():
        acc, dt, _ = make()
        rec = read_record(RECORDS / name)
        assert rec.dt == dt and rec.npts == acc.size
        # 7 printed digits; compared in value, not bytes (library versions may move ulps)
        np.testing.assert_allclose(rec.acc, acc, rtol=0, atol=1e-6 * rec.pga)
    assert at2_text(*make_records.sine_record()) == (RECORDS / "sine_1cycle.AT2").read_text()


def test_make_records_script_writes_checks_and_refuses_to_overwrite(tmp_path, capsys):
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import make_records
    finally:
        sys.path.remove(str(ROOT / "scripts"))
    assert make_records.main(["--out", str(tmp_path)]) == 0
    for name in make_records.FILES:
        assert read_record(tmp_path / name).npts == SHIPPED[name][0]
    assert make_records.main(["--check", "--out", str(tmp_path)]) == 0
    assert make_records.main(["--out", str(tmp_path)]) == 1
    assert "already exists; use --overwrite" in capsys.readouterr().err
    (tmp_path / "sine_1cycle.AT2").write_text("changed")
    assert make_records.main(["--check", "--out", str(tmp_path)]) == 1
