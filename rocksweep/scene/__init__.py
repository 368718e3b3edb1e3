"""Scenes: the YAML loader (``loader``), the ``Scene`` model (``model``), the validation
of every section against the one table of keys (``parse``, ``rocksweep.schema``), and the
cost admission (``admission``: every valid scene finishes in bounded time)."""

from rocksweep.scene.model import Axis, Scene
from rocksweep.scene.parse import MAX_POINTS, apply_overrides, load_scene, parse_scene

__all__ = ["MAX_POINTS", "Axis", "Scene", "apply_overrides", "load_scene",
           "parse_scene"]
