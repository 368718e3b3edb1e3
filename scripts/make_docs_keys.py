"""The scene key reference in docs/scenes.md, written from the one table of keys
(``rocksweep.schema.KEYS``): every key, what it takes and what is allowed.

    python scripts/make_docs_keys.py           # rewrite the table in docs/scenes.md
    python scripts/make_docs_keys.py --check   # exit 1 if docs/scenes.md is out of date

The table sits between two marker lines; the rest of the page is kept as written.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the tree this script is in, not an installed copy

from rocksweep.schema import KEYS  # noqa: E402 (after the path: this tree's schema)

PAGE = ROOT / "docs" / "scenes.md"
BEGIN = "<!-- keys: written by scripts/make_docs_keys.py from rocksweep/schema.py -->"
END = "<!-- end of keys -->"
KINDS = {"axis": "number, list or range", "number": "number", "integer": "integer",
         "choice": "word", "choices": "word or list (swept)", "bool": "true/false",
         "string": "text"}


def table() -> str:
    """The markdown table of every key of ``KEYS``, in the table's order."""
    rows = ["| key | takes | allowed | required |", "|---|---|---|---|"]
    for key, spec in KEYS.items():
        allowed = spec.allowed.removeprefix("must be ").replace("|", "\\|")
        required = "yes" if spec.required else (
            "no" if spec.default is None else f"no (default {spec.default})")
        rows.append(f"| `{key}` | {KINDS.get(spec.kind, spec.kind)} | {allowed} | "
                    f"{required} |")
    return "\n".join(rows)


def page_with_table(text: str) -> str:
    block = f"{BEGIN}\n\n{table()}\n\n{END}"
    if BEGIN in text and END in text:
        head, rest = text.split(BEGIN, 1)
        return head + block + rest.split(END, 1)[1]
    return text.rstrip() + "\n\n## Every key\n\n" + block + "\n"


def main(argv: list[str]) -> int:
    text = PAGE.read_text()
    new = page_with_table(text)
    if "--check" in argv:
        if new != text:
            print(f"{PAGE}: out of date with rocksweep/schema.py; run "
                  "python scripts/make_docs_keys.py")
            return 1
        print(f"{PAGE}: up to date ({len(KEYS)} keys)")
        return 0
    PAGE.write_text(new)
    print(f"wrote {PAGE} ({len(KEYS)} keys)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
