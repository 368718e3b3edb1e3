"""Scenes: the YAML loader, the ``Scene`` model, the validation of every section against
the one table of keys (``rocksweep.schema``), and the cost admission (every valid scene
finishes in bounded time)."""

from rocksweep.scene.scene import (
    MAX_POINTS,
    Axis,
    Scene,
    SceneError,
    apply_overrides,
    load_scene,
    parse_scene,
)

__all__ = ["MAX_POINTS", "Axis", "Scene", "SceneError", "apply_overrides", "load_scene",
           "parse_scene"]
