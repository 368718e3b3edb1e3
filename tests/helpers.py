"""Helpers shared by test modules (``from helpers import one_line_error``; pytest puts
tests/ on sys.path, there being no package)."""

from __future__ import annotations


def one_line_error(result, code: int | None = None) -> str:
    """The single line a failed CLI run printed (a click ``Result``): a non-zero exit
    (exactly ``code`` if given), no traceback, no exception but the exit, one line."""
    assert result.exit_code != 0, result.output
    if code is not None:
        assert result.exit_code == code, (result.exit_code, result.output)
    assert result.exception is None or isinstance(result.exception, SystemExit), \
        result.exception
    assert "Traceback" not in result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1, result.output
    return lines[0]
