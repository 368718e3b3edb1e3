"""Compile-time selection: a call that a variant's flags make dead is not even typed (numba).

numba types and lowers both branches of ``if FLAG:`` even when FLAG is a literal (its
dead-branch pruning does not read literal arguments; LLVM removes the dead code later),
so a call inside a dead branch still costs its compile time. ``skipped_when`` wraps a
function so that the choice is made while typing, by the flag's literal type.
"""

from numba.core import types
from numba.extending import overload

from rocksweep.kernel._cache import INLINE


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
