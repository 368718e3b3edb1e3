"""What a user gives as a scene: a path to a YAML file, YAML text or a dict with the YAML's
structure, and overrides as ``"KEY=VALUE"`` strings (the command line's ``--set``, VALUE is
YAML) or a mapping of dotted keys to Python values (``{"impact.lam": 0.4}``); ``load``
turns them into a validated ``Scene`` (the Python API's and the command line's way in).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, Union

import yaml

from rocksweep.errors import ApiError
from rocksweep.scene.model import Scene
from rocksweep.scene.parse import load_scene, parse_scene

if TYPE_CHECKING:
    from rocksweep.scene.model import Scene

SceneLike = Union[str, Path, Mapping[str, Any]]  # noqa: UP007 (a runtime alias on 3.10)


Overrides = Union[Sequence[str], Mapping[str, Any]]  # noqa: UP007


def _yaml_value(v: Any) -> str:
    """A Python value as the YAML text of a ``KEY=VALUE`` override (inf as .inf)."""
    if hasattr(v, "tolist"):  # numpy scalars and arrays
        v = v.tolist()
    if isinstance(v, tuple):
        v = list(v)
    text = yaml.safe_dump(v, default_flow_style=True, width=1 << 30).strip()
    return text[:-3].strip() if text.endswith("\n...") else text


def override_strings(overrides: Overrides | None) -> list[str]:
    """Overrides as ``KEY=VALUE`` strings: a sequence of such strings is kept, a mapping
    ``{dotted key: value}`` is written as YAML (``{"impact.lam": 0.4}`` -> impact.lam=0.4;
    ``__`` in a key stands for a dot, as in ``impact__lam``)."""
    if overrides is None:
        return []
    if isinstance(overrides, str):
        return [overrides]
    if isinstance(overrides, Mapping):
        out = []
        for k, v in overrides.items():
            if not isinstance(k, str):
                raise TypeError(f"overrides: key {k!r}: must be a string (a dotted scene "
                                "key, e.g. 'impact.lam')")
            out.append(f"{k.replace('__', '.')}={_yaml_value(_plain_tree(v, k))}")
        return out
    if isinstance(overrides, bytes | bytearray) or not isinstance(overrides, Iterable):
        raise TypeError(f"overrides = {overrides!r}: give KEY=VALUE strings "
                        "(['impact.lam=0.2']) or a mapping ({'impact.lam': 0.2})")
    items = list(overrides)
    for o in items:
        if not isinstance(o, str):
            raise TypeError(f"overrides: {o!r}: each override must be a KEY=VALUE string, "
                            "e.g. 'impact.lam=0.2'")
    return items


def load(scene: SceneLike | Scene, overrides: Overrides | None = ()) -> tuple[Scene, Path | None]:
    """A validated scene and the file it came from (None for text or a dict).

    scene: a ``Path``; a ``str`` with a newline (YAML), or that names an existing file,
    or else holds a colon (one line of YAML), or else is taken as a missing path; a
    mapping (the YAML's structure); or a ``Scene`` (then without overrides). Errors are
    one-line SceneErrors.
    """
    ov = override_strings(overrides)
    if isinstance(scene, Scene):
        if ov:
            raise ApiError("overrides apply to a scene path, text or dict, not to a Scene")
        return scene, None
    if isinstance(scene, Mapping):
        text = yaml.safe_dump(_plain_tree(scene), sort_keys=False, allow_unicode=False)
        return parse_scene(text, "scene", ov), None
    if isinstance(scene, str) and ("\n" in scene or (":" in scene and not _is_file(scene))):
        return parse_scene(scene, "scene", ov), None
    if not isinstance(scene, str | Path):
        raise ApiError(f"scene = {scene!r}: give a path, YAML text or a dict")
    path = Path(scene)
    # a missing file, a loop of links, a FIFO...: load_scene's one line
    return load_scene(path, ov), path


def _is_file(text: str) -> bool:
    try:
        return Path(text).is_file()
    except (OSError, ValueError):  # too long for a file name, NUL bytes
        return False


def _plain_tree(v: Any, where: str = "scene") -> Any:
    """A mapping with numpy values and tuples -> plain YAML-safe Python; a value YAML
    cannot hold (a complex number, an arbitrary object) is an ApiError naming where it
    is (``scene['pulse']['A_ratio']``)."""
    if isinstance(v, Mapping):
        return {str(k): _plain_tree(x, f"{where}[{k!r}]") for k, x in v.items()}
    if hasattr(v, "tolist") and not isinstance(v, str | bytes):
        try:
            v = v.tolist()
        except Exception:  # noqa: BLE001 - a foreign object's tolist: refused below
            pass
        else:
            return _plain_tree(v, where)
    if isinstance(v, list | tuple):
        return [_plain_tree(x, f"{where}[{i}]") for i, x in enumerate(v)]
    if v is None or isinstance(v, bool | str):
        return v
    if isinstance(v, int | float) and not isinstance(v, complex):
        return int(v) if isinstance(v, int) else float(v)
    raise ApiError(f"{where} = {_short_repr(v)}: not a scene value (numbers, strings, "
                   "booleans, lists and mappings of them)")


def _short_repr(v: Any) -> str:
    text = repr(v).replace("\n", " ")
    return text if len(text) <= 60 else text[:57] + "..."
