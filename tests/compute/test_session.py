"""One walk per sweep: ``rocksweep.run`` (and ``rocksweep sweep``) make the scene's grid
once, check the output path once and the sweep's arguments once, and hand them down."""

from __future__ import annotations

import sys

import pytest
from bodies import FIG3_YAML

import rocksweep
import rocksweep.compute.arguments
import rocksweep.compute.session
import rocksweep.outputs
import rocksweep.store.writer
from rocksweep.cli.main import main
from rocksweep.scene.grid import Grid

# 2 x 2 x 2 points
SCENE = FIG3_YAML + ("impact: {lam: [0.0, 0.4]}\n"
                     "pulse: {shape: sine, A_ratio: [2.0, 4.0], w_over_p: [0.5, 1.0]}\n")


@pytest.fixture
def counts(monkeypatch):
    """Calls of ``Grid(...)``, ``outputs.check_output`` and
    ``arguments.check_sweep_arguments``, wherever a rocksweep module holds them."""
    seen = {"Grid": 0, "check_output": 0, "check_sweep_arguments": 0}
    make = Grid.__init__

    def grid_init(self, *args, **kwargs):
        seen["Grid"] += 1
        make(self, *args, **kwargs)

    monkeypatch.setattr(Grid, "__init__", grid_init)
    for name, owner in (("check_output", rocksweep.outputs),
                        ("check_sweep_arguments", rocksweep.compute.arguments)):
        real = getattr(owner, name)

        def counted(*args, _real=real, _name=name, **kwargs):
            seen[_name] += 1
            return _real(*args, **kwargs)

        for module in list(sys.modules.values()):
            if (getattr(module, "__name__", "").startswith("rocksweep")
                    and getattr(module, name, None) is real):
                monkeypatch.setattr(module, name, counted)
    return seen


def test_run_into_a_file_makes_the_grid_once(counts, tmp_path):
    ds = rocksweep.run(SCENE, output=tmp_path / "r.h5")
    assert ds["outcome"].size == 8
    assert counts == {"Grid": 1, "check_output": 1, "check_sweep_arguments": 1}


def test_run_in_memory_makes_the_grid_once(counts):
    ds = rocksweep.run(SCENE)
    assert ds["outcome"].size == 8
    assert counts == {"Grid": 1, "check_output": 0, "check_sweep_arguments": 1}


def test_the_command_checks_its_arguments_once(counts, cli, tmp_path):
    (tmp_path / "s.yaml").write_text(SCENE)
    res = cli.invoke(main, ["sweep", str(tmp_path / "s.yaml"), "-o", str(tmp_path / "r.h5"),
                            "-q"])
    assert res.exit_code == 0, res.output
    assert counts["check_sweep_arguments"] == 1 and counts["check_output"] == 1
    assert counts["Grid"] == 1


def test_flags_take_python_and_numpy_bools_only():
    import numpy as np

    from rocksweep.analysis.boundaries import check_search
    from rocksweep.compute.arguments import check_flag
    from rocksweep.errors import ApiError

    assert check_flag("resume", np.True_) is True and check_flag("resume", False) is False
    assert check_search(np.False_) is False
    for bad in (1, "yes", np.int8(1), None):
        with pytest.raises(TypeError, match="must be True or False"):
            check_flag("resume", bad)
        with pytest.raises(ApiError, match="must be True or False"):
            check_search(bad)


def test_a_closed_dask_client_is_refused_by_its_type():
    distributed = pytest.importorskip("distributed")
    from rocksweep.compute.session import client_backend
    from rocksweep.errors import ApiError

    class Scheduler:
        address = "tcp://127.0.0.1:8786"

    class Closed(distributed.Client):  # dask's type, without a cluster
        def __init__(self) -> None:
            self.status, self.scheduler = "closed", Scheduler()

        def __repr__(self) -> str:
            return "<Client: closed>"

        def __del__(self) -> None:
            pass

    closed = Closed()
    with pytest.raises(ApiError, match="this dask Client is closed"):
        client_backend(closed)

    class LookAlike:  # named Client, with a scheduler, but not dask's
        status, scheduler = "closed", Scheduler()

    LookAlike.__name__ = "Client"
    assert client_backend(LookAlike()) == {"backend": "dask", "scheduler": Scheduler.address}
