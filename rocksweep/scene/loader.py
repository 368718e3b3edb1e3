"""The scene's YAML loader (``SceneLoader``): PyYAML's safe loader with YAML 1.2 numbers
(``1e-6`` is a number), a key given twice in a mapping refused, nesting limited to
MAX_DEPTH levels, the expansion of aliases bounded (MAX_EXPANDED, an alias bomb is refused
before it is built) and control characters refused. Problems raise ``YamlError``."""

from __future__ import annotations

import re
from typing import Any

import yaml

from rocksweep.schema import fmt

# Nesting of the scene's YAML (a scene needs 3 levels: section, key, range or list).
# PyYAML composes nodes recursively; 3000 levels would end in a RecursionError.
MAX_DEPTH = 20
# Expanded size of a scene's YAML [characters of scalars + nodes], aliases counted at each
# use, beyond the text's own length: an alias bomb (9 levels of 9 aliases in 640 bytes)
# expands to ~4e8 nodes and took 4 GB and 35 s to build; it is refused before it is built.
MAX_EXPANDED = 4_000_000


class YamlError(Exception):
    """A YAML text the scene refuses; ``str()`` says where (1-based line) and why."""


class SceneLoader(yaml.SafeLoader):
    """PyYAML's safe loader with YAML 1.2 numbers, no duplicate keys and a depth limit.

    PyYAML follows YAML 1.1, where a float needs a dot and a signed exponent: ``1e-6`` and
    ``1E+3`` would be strings. The resolver added below reads them as numbers (YAML 1.2's
    core schema).
    """

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._depth = 0
        self._limit = max(MAX_EXPANDED, 2 * len(stream))

    def get_single_data(self) -> Any:
        node = self.get_single_node()
        if node is None:
            return None
        self._check_expanded(node)
        return self.construct_document(node)

    def _check_expanded(self, root: yaml.Node) -> None:
        """Refuse a document whose expansion (aliases repeated at every use) exceeds the
        limit, counting on the composed graph (each node once, memoised): nothing of the
        expansion is built."""
        sizes: dict[int, int] = {}
        active: set[int] = set()

        def size(node: yaml.Node) -> int:
            key = id(node)
            if key in sizes:
                return sizes[key]
            if key in active:
                raise YamlError(f"error at line {node.start_mark.line + 1}: an alias "
                                 "refers to a node that contains it (a recursive structure)")
            active.add(key)
            if isinstance(node, yaml.ScalarNode):
                n = 1 + len(node.value)
            elif isinstance(node, yaml.SequenceNode):
                n = 1 + sum(size(x) for x in node.value)
            else:
                n = 1 + sum(size(k) + size(v) for k, v in node.value)
            active.discard(key)
            if n > self._limit:
                raise YamlError(f"expands to more than {self._limit:,} characters (aliases "
                                 "repeated at every use, e.g. an alias bomb); write the "
                                 "values out or use fewer aliases")
            sizes[key] = n
            return n

        size(root)

    def compose_node(self, parent: Any, index: Any) -> Any:
        self._depth += 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise YamlError(f"error at line {mark.line + 1}: nested more than "
                                 f"{MAX_DEPTH} levels deep")
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict:
        seen: set = set()
        for key_node, _ in node.value:
            if key_node.tag == "tag:yaml.org,2002:merge":
                continue
            key = self.construct_object(key_node, deep=True)
            try:
                dup = key in seen
                seen.add(key)
            except TypeError:  # an unhashable key: PyYAML reports it below
                continue
            if dup:
                raise YamlError(f"error at line {key_node.start_mark.line + 1}: key "
                                 f"{fmt(key)} given twice in one mapping")
        return super().construct_mapping(node, deep=deep)


SceneLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
    list("-+0123456789."))


_NOT_YAML = re.compile(  # PyYAML's reader refuses these (yaml.reader.Reader.NON_PRINTABLE)
    r"[^\x09\x0a\x0d\x20-\x7e\x85\xa0-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]")
CONTROL_CHARS = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")  # C0 controls but tab and newline


def _control_character(text: str) -> str | None:
    """Where ``text`` holds a character YAML refuses to read (NUL, BEL, ESC, other C0/C1
    controls but tab and newlines): 'character 0x07 at line 2, column 7', or None."""
    m = _NOT_YAML.search(text)
    if m is None:
        return None
    line = text.count("\n", 0, m.start()) + 1
    column = m.start() - (text.rfind("\n", 0, m.start()) + 1) + 1
    return f"character {ord(m.group()):#04x} at line {line}, column {column}"


def load_yaml(text: str) -> Any:
    """Parse YAML text with ``SceneLoader``; problems raise ``YamlError``."""
    bad = _control_character(text)
    if bad is not None:
        raise YamlError(f"error: {bad} is a control character (NUL, BEL, ESC...); a "
                         "scene is plain text")
    loader = SceneLoader(text)
    try:
        return loader.get_single_data()
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        problem = getattr(err, "problem", None) or "invalid YAML"
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        raise YamlError(f"syntax error{where}: {problem}") from None
    except RecursionError:
        raise YamlError("error: nested too deeply") from None
    finally:
        loader.dispose()
