"""One home for each enumerated concept (``rocksweep.vocab``): a list of its names typed
again anywhere else in the package fails here, as the docs-keys test fails on a key
table that drifted from the schema.

A "list" is a tuple, list or set literal (not ``__all__``'s names of Python objects), or
the keys of a dict literal, holding two or more names of one family, or a string (not a
docstring) naming every member of a family of three or more (a message such as "must be
sine, cosine, ricker or mp"). Single names in comparisons (``law == CONSTANT``) are uses,
not definitions, and stay free; a few single words (``WORDS``: the attribute naming a
Dataset's kind) have one home and are typed nowhere else.
"""

from __future__ import annotations

import ast
import math
import re
from pathlib import Path

import pytest
from helpers import docstring_ids

from rocksweep.vocab import axes, ground, kinds, laws, outcomes, phases, settings

PKG = Path(__file__).resolve().parents[1] / "rocksweep"

FAMILIES: dict[str, tuple[str, ...]] = {
    "impact laws": laws.LAWS,
    "pulse shapes": (*ground.SHAPES, ground.RECORD),
    "intensity measures": tuple(ground.SCALE_IMS),
    "outcome words": tuple(outcomes.OUTCOME_CODE),
    "status words": tuple(outcomes.STATUS_BIT),
    "fragility states": outcomes.STATES,
    "computed flags": tuple(outcomes.COMPUTED_CODE),
    "accuracy presets": settings.PRESET_NAMES,
    "event root finders": settings.ROOTS,
    "accuracy ladders": settings.LADDER_NAMES,
    "alpha_ref keys": axes.ALPHA_KEYS,
    "alpha_ref LaTeX": tuple(tex for _, tex in axes.ALPHA_REF.values()),
    "contact phases": phases.PHASES,
    "dataset kinds": kinds.KIND_NAMES,
    "IM components": ground.COMPONENTS,
    "missing components": ground.MISSING,
    "orientation answers": ground.ORIENTATIONS,
}
# Single words with one home: typed as a string anywhere else (not in a docstring) they fail.
WORDS: dict[str, str] = {
    kinds.KIND_ATTR: "the kind attribute (vocab.kinds.KIND_ATTR)",
}
# Concepts whose values (not names) live elsewhere, keyed by the vocabulary's names: the
# one dict literal allowed, checked to hold exactly the vocabulary's names below.
HOMES = {
    ("accuracy ladders", "rocksweep/analysis/accuracy.py"),
}


def _strings(nodes) -> list[str]:
    return [n.value for n in nodes if isinstance(n, ast.Constant) and isinstance(n.value, str)]


def redefinitions(src: str, where: str) -> list[str]:
    """Lines of ``src`` that type a list of one family's names (see the module docstring)."""
    tree = ast.parse(src)
    docs = docstring_ids(tree)
    exports = {id(node.value) for node in ast.walk(tree)  # module names, not vocabulary
               if isinstance(node, ast.Assign)
               and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets)}
    found = []
    for node in ast.walk(tree):
        if id(node) in exports:
            continue
        if isinstance(node, ast.IfExp):  # "alpha" if block else "alpha_cg": a mapping
            pair = set(_strings([node.body, node.orelse]))
            found += [f"{where}:{node.lineno}: {family} chosen by a condition"
                      for family, members in FAMILIES.items()
                      if len(pair) == 2 and pair == set(members)]
            continue
        if isinstance(node, ast.Tuple | ast.List | ast.Set):
            names = _strings(node.elts)
        elif isinstance(node, ast.Dict):
            names = _strings(k for k in node.keys if k is not None)
        elif (isinstance(node, ast.Constant) and isinstance(node.value, str)
              and id(node) not in docs):
            if node.value in WORDS:
                found.append(f"{where}:{node.lineno}: {WORDS[node.value]}")
            words = set(re.findall(r"[A-Za-z_][A-Za-z0-9_]*", node.value))
            for family, members in FAMILIES.items():
                if len(members) >= 3 and set(members) <= words:
                    found.append(f"{where}:{node.lineno}: {family} in a string")
            continue
        else:
            continue
        reported: list[set[str]] = []
        for family, members in FAMILIES.items():
            hits = set(names) & set(members)
            if len(hits) < 2 or (family, where) in HOMES or any(hits <= r for r in reported):
                continue  # (mode1, mode2 are outcome words and fragility states: once)
            reported.append(hits)
            found.append(f"{where}:{node.lineno}: {family} {sorted(hits)}")
        if not isinstance(node, ast.Dict) and set(axes.DIAGRAM_AXES) <= set(names):
            found.append(f"{where}:{node.lineno}: the diagram axes (vocab.axes.DIAGRAM_AXES)")
        if isinstance(node, ast.Dict) and len(set(names) & set(axes.AXES)) >= 3:
            marks = [v for v in _strings(node.values) if "\\" in v or "[" in v]
            if len(marks) >= 2:  # LaTeX symbols or units of axes: a copy of vocab.axes
                found.append(f"{where}:{node.lineno}: a table of axis symbols or units")
    return found


def test_no_list_of_vocabulary_names_outside_the_vocabulary():
    found = []
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG.parent).as_posix()
        if rel.startswith("rocksweep/vocab/"):
            continue
        found += redefinitions(path.read_text(), rel)
    assert not found, "names typed outside rocksweep.vocab:\n" + "\n".join(found)


def test_the_checker_sees_a_copy():
    src = ('LAWS = ("vertical", "locked", "constant")\n'
           'msg = "must be sine, cosine, ricker, mp or record"\n'
           'for d in ("w_over_p", "A_ratio"): pass\n'
           'row = {"w_over_p": 1.0, "A_ratio": 2.0}\n'
           'key = "alpha" if kind == "block" else "alpha_cg"\n'
           'word = "mode1" if m == 1 else "mode2"\n'
           'ok = law == "constant"\n'
           'def f():\n    """vertical, locked, constant in a docstring is prose."""\n'
           'attrs = {"rocksweep_kind": "ida"}\n'
           'ANSWERS = ("each", "worst")\n'
           'how = "skip" if lenient else "error"\n')
    found = sorted(redefinitions(src, "x.py"), key=lambda f: int(f.split(":")[1]))
    assert found == ["x.py:1: impact laws ['constant', 'locked', 'vertical']",
                     "x.py:2: pulse shapes in a string",
                     "x.py:3: the diagram axes (vocab.axes.DIAGRAM_AXES)",
                     "x.py:5: alpha_ref keys chosen by a condition",
                     "x.py:10: the kind attribute (vocab.kinds.KIND_ATTR)",
                     "x.py:11: orientation answers ['each', 'worst']",
                     "x.py:12: missing components chosen by a condition"]


def test_the_homes_hold_the_vocabulary_names():
    from rocksweep.analysis.accuracy import LADDERS
    from rocksweep.numerics import PRESETS

    assert tuple(PRESETS) == settings.PRESET_NAMES
    assert tuple(LADDERS) == settings.LADDER_NAMES


def test_kernel_codes_are_the_vocabulary_codes():
    from rocksweep.kernel import layout as L  # noqa: N812

    assert [L.SHAPE_SINE, L.SHAPE_COSINE, L.SHAPE_RICKER, L.SHAPE_MP, L.SHAPE_RECORD] == [
        ground.SHAPE_CODE[s] for s in (*ground.SHAPES, ground.RECORD)]
    assert [L.LAW_EQ1, L.LAW_LOCKED, L.LAW_CONSTANT] == [laws.LAW_CODE[w]
                                                               for w in laws.LAWS]
    assert [L.ROOT_BISECT, L.ROOT_ILLINOIS, L.ROOT_HERMITE] == [settings.ROOT_CODE[w]
                                                                for w in settings.ROOTS]
    assert len(set(settings.ROOT_CODE.values())) == len(settings.ROOT_CODE)
    from rocksweep.kernel import sliding

    # a phase's code is 2 (rocking) + 1 (slipping) of its corner s and slip sigma
    assert [sliding.phase_code(s, sg) for s, sg in ((0, 0), (0, 1), (1, 0), (-1, -1))] == [
        phases.PHASE_CODE[w] for w in phases.PHASES]
    # codes distinct, status bits one bit each
    assert len(set(ground.SHAPE_CODE.values())) == len(ground.SHAPE_CODE)
    assert all(b & (b - 1) == 0 for b in outcomes.STATUS_BIT.values())
    assert L.STATUS_FLAGGED == sum(outcomes.STATUS_BIT[w] for w in outcomes.FLAGGED_WORDS)


@pytest.mark.parametrize("shape, cycles, gamma, want", [
    ("sine", 1, 2.0, 2 * math.pi), ("cosine", 3, 2.0, 6 * math.pi),
    ("ricker", 1, 2.0, 6 * math.pi), ("mp", 1, 2.5, 5 * math.pi)])
def test_pulse_durations(shape, cycles, gamma, want):
    assert ground.pulse_duration(shape, cycles, gamma) == pytest.approx(want, rel=1e-15)


def test_axis_labels_name_units_and_the_body_kind():
    assert axes.label("alpha_cg") == r"$\alpha_{cg}$ [rad]"
    assert axes.label("A_ratio", "block") == r"$A/(g\,\tan\alpha)$"
    assert axes.label("PGV") == "$PGV$ [m/s]"
    assert axes.symbol("A_ratio", "flexible") == "A/(g tan alpha_cg)"
    assert axes.label("unknown_axis") == "unknown_axis"


def test_e_max_is_labelled_by_the_impact_law_not_eq_1_alone():
    """e_max once said "(eq. 1)" under every impact law, whose formula it is not."""
    from rocksweep import fields

    meaning = fields.BY_NAME["e_max"].meaning
    assert "impact.law" in meaning and not meaning.endswith("(eq. 1)")
