"""The ``rocksweep`` group, shared options, and the one error path to the user.

Each command lives in its own module and is thin: it turns options into arguments and
calls the library. Errors the user can fix (a bad scene, a foreign file, an existing
output) reach the terminal as one line through ``click.ClickException``: no traceback, a
non-zero exit. The library's messages name the arguments of its functions
(``rocksweep.errors.Arg``); the command line says them as its options (``option_words``):
the one place that knows the options' names.
"""

from __future__ import annotations

import functools
import warnings
from pathlib import Path

import click

import rocksweep
from rocksweep.errors import Arg, RocksweepError, Said, one_line

# The library's argument names whose option is not ``--NAME`` (underscores as dashes)
OPTIONS = {"overrides": "--set", "output": "-o"}


def option_words(arg: Arg) -> str:
    """An argument a library message names, said as the command line's option: ``rtol =
    0.3`` as ``--rtol 0.3``, ``resume=True`` as ``--resume``, ``overrides={'pulse.A_ratio':
    ...}`` as ``--set pulse.A_ratio=VALUE``, ``joint=False`` as ``without --joint``."""
    option = OPTIONS.get(arg.name, f"--{arg.name.replace('_', '-')}")
    if arg.kind == "set_key":
        return f"--set {arg.value}"
    if arg.kind == "set_fix":
        return f"--set {arg.value}=VALUE"
    if arg.kind == "set_entry":
        return f"--set {arg.value!r}"
    if arg.kind == "keyword":
        return f"{option} VALUE"
    if arg.kind == "flag" and arg.value is False:
        return f"without {option}"
    if arg.kind == "flag" or not arg.given:
        return option
    return f"{option} {arg.value}"


def said(err: RocksweepError) -> str:
    """A library error as the command line says it: one line, naming its options."""
    return one_line(err.said(option_words))


def warning_line(message: Warning | str) -> str:
    """A library warning as the command line says it: ``Warning: ...``, one line, naming
    its options (``said``) where it names arguments (a ``Said`` warning)."""
    text = message.said(option_words) if isinstance(message, Said) else str(message)
    return f"Warning: {one_line(text)}"


class InputError(click.ClickException):
    """Bad input (a scene value, a file, an argument the library refuses): one line,
    ``Error: ...``, exit 2 as click's usage errors; nothing was written."""

    exit_code = 2


class _HeldWarnings:
    """The library's warnings during one command, held until it can no longer refuse:
    said (``warning_line``) when it releases them (``release_warnings``) or ends, dropped
    when it refuses, so that a refusal is its one line (a scene's record warning or a
    fit's verdict before "Error: ..." was a second line about a run that did not
    happen)."""

    def __init__(self) -> None:
        self.held: list[Warning | str] = []
        self.released = False

    def show(self, message, category, filename, lineno, file=None, line=None) -> None:
        if self.released:
            click.echo(warning_line(message), err=True)
        else:
            self.held.append(message)

    def release(self) -> None:
        self.released = True
        held, self.held = self.held, []
        for message in held:
            click.echo(warning_line(message), err=True)


_HOLDS: list[_HeldWarnings] = []  # the running commands' (one, or nested in tests)


def release_warnings() -> None:
    """Say the running command's held warnings now, and later ones as they come: a
    command calls it once nothing it still checks can refuse (a sweep before its first
    point, an analysis once it has fitted), so its warnings precede its work and output."""
    if _HOLDS:
        _HOLDS[-1].release()


def user_errors(fn):
    """Turn the library's user-facing errors (``RocksweepError``) into one-line click
    errors naming the command line's options (``said``); the library's warnings are held
    until the command can no longer refuse (``_HeldWarnings``)."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        hold = _HeldWarnings()
        before = warnings.showwarning
        warnings.showwarning = hold.show
        _HOLDS.append(hold)
        try:
            result = fn(*args, **kwargs)
        except RocksweepError as err:
            raise InputError(said(err)) from None  # the refusal alone: held ones dropped
        except click.ClickException as err:
            if type(err) is click.ClickException:  # a command's own one-line refusal
                err.exit_code = InputError.exit_code
            raise
        except Exception:
            hold.release()  # not a refusal (a fault): everything said
            raise
        finally:
            _HOLDS.remove(hold)
            warnings.showwarning = before
        hold.release()
        return result

    return wrapper


def load(scene_path: Path, overrides: tuple[str, ...] = ()):
    """The validated scene at ``scene_path`` (imports the scene machinery, and with it
    numba, only when a command runs: ``rocksweep --help`` stays fast)."""
    # the scene machinery loads numpy and numba (~1 s): not at --help
    from rocksweep.scene.parse import load_scene

    # a missing file, a loop of links, a FIFO...: load_scene's one line (input_problem)
    return load_scene(scene_path, list(overrides))


def _print_version(ctx: click.Context) -> None:
    """``rocksweep --version``: the version, read only when asked."""
    click.echo(f"rocksweep {rocksweep.__version__}")
    ctx.exit()


class OneLineUsageError(click.UsageError):
    """A bad option value or a missing argument, said in one line (click's usage errors
    print the usage and a hint first): "Error: ..." and exit code 2."""

    def show(self, file=None) -> None:
        click.echo(f"Error: {one_line(self.format_message())}", err=True, file=file)


class OneLineCommand(click.Command):
    def parse_args(self, ctx: click.Context, args: list[str]) -> list[str]:
        try:
            return super().parse_args(ctx, args)
        except click.UsageError as err:
            raise OneLineUsageError(err.format_message(), err.ctx) from None


class OneLineGroup(click.Group):
    """The group whose commands answer bad usage in one line, and Ctrl-C with exit 130
    and one line (click would say "Aborted!" with exit 1): also when the interrupt was
    swallowed by a library callback and surfaced as another error
    (``rocksweep.interrupts``)."""

    command_class = OneLineCommand

    def invoke(self, ctx: click.Context):
        # interrupts (signal): +2% of --help, needed once a command runs
        from rocksweep import interrupts

        try:
            return super().invoke(ctx)
        except (SystemExit, click.exceptions.Exit):
            raise
        except BaseException as err:
            if isinstance(err, KeyboardInterrupt) or interrupts.pending():
                click.echo("\ninterrupted", err=True)
                raise SystemExit(130) from None
            raise

    def resolve_command(self, ctx: click.Context, args: list[str]):
        try:
            return super().resolve_command(ctx, args)
        except click.UsageError as err:
            raise OneLineUsageError(err.format_message(), err.ctx) from None


@click.group(cls=OneLineGroup, context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--version", "-V", is_flag=True, expose_value=False, is_eager=True,
              callback=lambda ctx, _param, value: _print_version(ctx) if value else None,
              help="Show the version and exit.")
def main() -> None:
    """Stability diagrams of flexible rocking oscillators (Zhu, Chatzis & Acikgoz).

    Times are p*t, rotations theta/alpha_cg, energies E/E_ref.
    """
    _one_line_warnings()


def _one_line_warnings() -> None:
    """The library's warnings (a drifting record, a large scale factor) as one line on
    stderr, ``Warning: ...``, instead of Python's two (file, line, source)."""
    def show(message, category, filename, lineno, file=None, line=None) -> None:
        click.echo(warning_line(message), err=True)

    warnings.showwarning = show
