"""Shared fixtures: the paper's bodies (Tables 2 and 3), a CLI runner, device nodes."""

import os
import stat

import pytest
from bodies import BODY2, BODY3, BODY4, FIG3
from click.testing import CliRunner

from rocksweep.physics.bodies import FlexibleBody


@pytest.fixture(scope="session")
def body_fig2() -> FlexibleBody:
    """Table 2: stocky, laterally flexible body of Figure 2."""
    return BODY2


@pytest.fixture(scope="session")
def body_fig3() -> FlexibleBody:
    """Table 3, Figure 3: slender flexible body (wn/p = 2.43)."""
    return BODY3


@pytest.fixture(scope="session")
def body_fig4() -> FlexibleBody:
    """Table 3, Figure 4: slender stiff body (wn/p = 9.82)."""
    return BODY4


@pytest.fixture()
def cli():
    return CliRunner()


@pytest.fixture()
def device_node(tmp_path):
    """make(name, minor) -> a character device in tmp_path with the numbers of /dev/null
    (1, 3) or /dev/full (1, 7). Tests of device refusal write at these, never at the
    machine's own /dev/null: a regression then replaces a node in tmp_path, not /dev/null
    (it happened once during development). Needs root (CAP_MKNOD), as CI has."""

    def make(name: str = "null.h5", minor: int = 3):
        path = tmp_path / name
        os.mknod(path, 0o666 | stat.S_IFCHR, os.makedev(1, minor))
        return path

    return make


@pytest.fixture(scope="session")
def suite_result(tmp_path_factory):
    """A small finished record-suite sweep (for the suite analyses): 6 records of
    records/suite x 6 PGA stripes x 2 lam, written to a result file."""
    import warnings
    from pathlib import Path

    import rocksweep

    root = Path(__file__).resolve().parents[1]
    scene = {"name": "small suite",
             "body": {**FIG3},
             "impact": {"lam": [0.0, 0.4]},
             "ground": {"records": [str(root / "records" / "suite" / f"SYN{i:02d}.AT2")
                                    for i in range(1, 7)],
                        "scale": {"im": "PGA", "values": {"start": 0.2, "stop": 1.6,
                                                          "num": 6}},
                        "p": 2.0, "periods": [0.2, 1.0]}}
    path = tmp_path_factory.mktemp("suite") / "suite.h5"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # large scale factors: said elsewhere
        rocksweep.run(scene, output=path, jobs=1)
    return path
