"""Numbers in README.md and docs/ that a command produces, regenerated from that command.

Each number lives in a marked block of a page (``<!-- numbers:NAME -->`` ... ``<!-- end
numbers:NAME -->``); the blocks are written from ``docs/numbers.json``, which holds what
the command computed (and the command). Hand edits inside a block are overwritten, and
``tests/test_docs_numbers.py`` checks that every block is the rendering of the stored
numbers.

    python scripts/make_docs_numbers.py            # recompute every number, rewrite blocks
    python scripts/make_docs_numbers.py --render   # rewrite the blocks from numbers.json
    python scripts/make_docs_numbers.py --check    # recompute; exit 1 if a number moved

Numbers (``COMPUTE``):

- ``impact_laws``: the mode 1 share of the 80 x 80 grid of ``configs/impact-laws.yaml``
  per law and lam (``rocksweep sweep``; ~1 min on 2 cores): the table of
  docs/impact_laws.md and the sentence of README.md.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import _here  # noqa: F401 (this checkout's package first)

ROOT = Path(__file__).resolve().parents[1]
STORE = ROOT / "docs" / "numbers.json"
LAWS = ("vertical", "locked", "constant")


def compute_impact_laws() -> dict:
    """{law: {lam: mode 1 share in %}} of configs/impact-laws.yaml (one decimal)."""
    import numpy as np

    from rocksweep.compute.driver import sweep_arrays
    from rocksweep.kernel import layout as L  # noqa: N812
    from rocksweep.scene.parse import load_scene

    scene = load_scene(ROOT / "configs" / "impact-laws.yaml")
    out = np.asarray(sweep_arrays(scene, jobs=2)[0]["outcome"])
    names = [a.name for a in scene.swept]
    lam_i, law_i = names.index("lam"), names.index("law")
    lams = scene.axis("lam").values
    laws = scene.axis("law").values
    shares: dict[str, dict[str, float]] = {}
    for j, law in enumerate(laws):
        shares[str(law)] = {}
        for i, lam in enumerate(lams):
            cut = np.take(np.take(out, [i], axis=lam_i), [j], axis=law_i)
            shares[str(law)][f"{lam:g}"] = round(
                100.0 * float(np.mean(cut == L.OUTCOME_MODE1)), 1)
    return {"command": "rocksweep sweep configs/impact-laws.yaml (outcome == mode1 share "
                       "of the 80 x 80 grid)", "shares": shares}


COMPUTE = {"impact_laws": compute_impact_laws}


def _pct(v: float) -> str:
    return f"{v:.1f}%"


def render_impact_laws(d: dict) -> dict[str, str]:
    """page -> the text of its ``impact_laws`` block."""
    s = d["shares"]
    lams = list(s["vertical"])
    rows = ["| lam | vertical | locked | constant (e = 0.77) |", "|---|---|---|---|"]
    rows += [f"| {lam} | " + " | ".join(_pct(s[law][lam]) for law in LAWS) + " |"
             for lam in lams]
    lo, hi = lams[0], lams[-1]
    const = {_pct(s["constant"][lam]) for lam in lams}
    const_text = (f"{const.pop()} at both" if len(const) == 1 else
                  " / ".join(_pct(s["constant"][lam]) for lam in lams))
    sentence = (f"On the Figure 3(a) body, the locked law (less energy lost at impact) "
                f"overturns {_pct(s['locked'][lo])} /\n{_pct(s['locked'][hi])} of the grid "
                f"in mode 1 at lam {lo} / {hi} against eq. (1)'s {_pct(s['vertical'][lo])} /"
                f" {_pct(s['vertical'][hi])}, mostly at\nhigh frequencies and amplitudes. A "
                f"constant e ignores lam ({const_text}), so the growth of\nmode 1 with lam "
                "belongs to the impulse-position laws.")
    return {"docs/impact_laws.md": "\n".join(rows), "README.md": sentence}


RENDER = {"impact_laws": render_impact_laws}


def _markers(name: str) -> tuple[str, str]:
    return f"<!-- numbers:{name} -->", f"<!-- end numbers:{name} -->"


def blocks(text: str) -> dict[str, str]:
    """name -> the text inside each marked block of a page."""
    return {m.group(1): m.group(2).strip("\n") for m in re.finditer(
        r"<!-- numbers:(\w+) -->\n(.*?)\n<!-- end numbers:\1 -->", text, flags=re.S)}


def with_block(text: str, name: str, body: str) -> str:
    begin, end = _markers(name)
    if begin not in text or end not in text:
        raise SystemExit(f"no block {begin} ... {end}")
    head, rest = text.split(begin, 1)
    return head + f"{begin}\n{body}\n{end}" + rest.split(end, 1)[1]


def pages(numbers: dict) -> dict[Path, str]:
    """Every page with its blocks written from ``numbers``."""
    out: dict[Path, str] = {}
    for name, render in RENDER.items():
        for page, body in render(numbers[name]).items():
            path = ROOT / page
            out[path] = with_block(out.get(path, path.read_text()), name, body)
    return out


def main(argv: list[str]) -> int:
    stored = json.loads(STORE.read_text()) if STORE.exists() else {}
    if "--render" not in argv:
        fresh = {name: fn() for name, fn in COMPUTE.items()}
        if "--check" in argv:
            moved = [n for n in fresh if fresh[n] != stored.get(n)]
            for n in moved:
                print(f"{n}: computed {json.dumps(fresh[n])}, stored "
                      f"{json.dumps(stored.get(n))}")
            print("up to date" if not moved else "out of date: run "
                  "python scripts/make_docs_numbers.py")
            return 1 if moved else 0
        stored.update(fresh)
        STORE.write_text(json.dumps(stored, indent=2) + "\n")
    for path, text in pages(stored).items():
        path.write_text(text)
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
