"""Compile-time selection: a variant's choices made while typing, by a literal's value (numba).

numba types and lowers both branches of ``if FLAG:`` even when FLAG is a literal (its
dead-branch pruning does not read literal arguments; LLVM removes the dead code later),
so a call inside a dead branch still costs its compile time. ``chosen`` picks one
function of a table by the value of a literal key (a variant's GROUND or REACTIONS:
integer or boolean literals, ``variants``) while typing, so that the others are not typed
or compiled at all; ``skipped_when`` makes a call that a flag makes dead a constant.

Each choice costs one small compile: the chosen entry itself is the overload's
implementation (so it takes the key first), compiled once per signature and inlined by
LLVM (``_cache.INLINE``). A wrapper in between would be one more compiled function, and a
compiled function is one more LLVM optimisation of everything it calls (a wrapper around
the loop cost the cold compile ~7%).
"""

from numba.core import errors, types
from numba.extending import overload

from rocksweep.kernel._cache import INLINE


def chosen(table: dict, name: str):
    """A function ``g(KEY, *args)``: ``table[KEY](KEY, *args)``, the entry picked while
    typing by KEY's literal value (``Literal[int]`` or ``Literal[bool]``, as the variants
    pass their flags); the other entries are not typed. Entries are plain-Python functions
    of (KEY, *args) (they are the implementation: a jitted function is called from one).
    A KEY that is not a literal is a typing error (jitted code only; plain Python,
    NUMBA_DISABLE_JIT=1: ``table[KEY](KEY, *args)``)."""

    def stub(key, *args):
        """Plain Python (NUMBA_DISABLE_JIT=1): the overload's choice, by value."""
        return table[key](key, *args)

    @overload(stub, jit_options=INLINE, prefer_literal=True, strict=False)
    def _select(key, *args):
        if isinstance(key, types.Literal):
            if key.literal_value not in table:
                raise errors.TypingError(f"{name}: no entry for {key.literal_value!r} "
                                         f"(entries: {sorted(table)})")
            return table[key.literal_value]
        raise errors.TypingError(f"{name}: its key must be a literal (a variant's flag: a "
                                 f"constant or a literal argument), not {key}")

    stub.__name__ = stub.__qualname__ = name
    return stub


def skipped_when(value, fn, result):
    """A function ``g(FLAG, *args)``: ``fn(*args)``, or the constant ``result`` when FLAG is
    the literal ``value`` (``Literal[bool]``, as the variants' flags are), in which case
    ``fn`` is not typed or compiled at all. Callable from jitted code only."""

    def stub(flag, *args):
        """Plain Python (NUMBA_DISABLE_JIT=1): the overload's choice."""
        if isinstance(flag, bool) and flag == value:
            return result
        return fn(*args)

    @overload(stub, jit_options=INLINE, prefer_literal=True)
    def _select(flag, *args):
        if isinstance(flag, types.BooleanLiteral) and flag.literal_value == value:
            def skipped(flag, *args):
                return result
            return skipped

        def called(flag, *args):
            return fn(*args)
        return called

    stub.__name__ = stub.__qualname__ = f"{fn.__name__}_unless_{value}"
    return stub
