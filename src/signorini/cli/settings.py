"""A run's settings: the loop's options and the flags that decide its files, from the command
line or, with ``--resume``, from the interrupted run's manifest."""

from __future__ import annotations

import argparse
import json
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path

from ..algebra.backends.selection import solver_factory
from ..loop.options import LEGACY_KEYS, AdaptiveOptions, OptionError
from .parser import FILE_FLAGS, OPTION_FLAGS, flag

__all__ = ["RunSettings", "new_settings", "recorded_arguments", "resumed_settings"]

#: what each recorded argument is, as the command line's parser gives it (a field no flag
#: sets, ``warm_start``, is recorded as the switch it is)
_KINDS = {
    **{f.name: type(f.default).__name__ for f in fields(AdaptiveOptions)},
    "solver": "str",
    **{name: "bool" for name in FILE_FLAGS},
}
_KIND_TEXT = {"bool": "true or false", "int": "an integer", "float": "a number", "str": "a name"}


@dataclass(frozen=True)
class RunSettings:
    """What decides a run's numbers and files; recorded in its manifest as ``arguments``.

    Attributes
    ----------
    options : AdaptiveOptions
    no_vtu, compare_uniform : bool
        ``--no-vtu``, ``--compare-uniform``.
    """

    options: AdaptiveOptions
    no_vtu: bool = False
    compare_uniform: bool = False

    def record(self) -> dict[str, object]:
        """The manifest's ``arguments``: the options by field (the solver by its name), and
        the file flags."""
        files = {name: getattr(self, name) for name in FILE_FLAGS}
        return {**self.options.to_record(), **files}


def _checked(build, *args: object) -> AdaptiveOptions:
    """``build(*args)``, an option's error spelt with its flag (``--max-levels must ...``)."""
    try:
        return build(*args)
    except OptionError as exc:
        message = str(exc)
        if message.startswith(exc.field):
            message = message[len(exc.field) :]
        raise ValueError(flag(exc.field) + message) from None


def _given(args: argparse.Namespace, dest: str) -> object:
    """A flag's value, None where it was not given (an unset switch is not given)."""
    value = getattr(args, dest)
    return None if value is False else value


def new_settings(args: argparse.Namespace) -> RunSettings:
    """The settings of a new run: the flags given, the options' defaults for the others.

    Raises
    ------
    ValueError
        For a bad value, naming its flag.
    """
    changes = {}
    for dest, field in OPTION_FLAGS.items():
        value = _given(args, dest)
        if value is not None:
            changes[field] = solver_factory(value) if field == "solver" else value
    options = _checked(lambda: AdaptiveOptions(**changes))
    return RunSettings(options, **{name: bool(getattr(args, name)) for name in FILE_FLAGS})


def _is_kind(value: object, kind: str) -> bool:
    """Whether a JSON value is what the parser gives for ``kind`` (``int`` for
    ``--max-ndof``: neither a bool, nor a float such as ``Infinity``)."""
    if kind == "bool":
        return isinstance(value, bool)
    if kind == "int":
        return isinstance(value, int) and not isinstance(value, bool)
    if kind == "float":
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    return isinstance(value, str)


def recorded_arguments(manifest: Mapping[str, object], file: Path) -> dict[str, object]:
    """The ``arguments`` a run's manifest records, checked as strictly as the command line
    checks its flags (the values :class:`~signorini.loop.AdaptiveOptions` then checks are
    those the parser can give: ``max_ndof`` an integer, as ``--max-ndof`` takes).

    Parameters
    ----------
    manifest : mapping
        The manifest (:attr:`signorini.output.run.RunFolder.manifest`).
    file : Path
        The manifest's file, for the messages.

    Raises
    ------
    ValueError
        Naming the file and the first argument that is unknown or of another kind.
    """
    stored = manifest.get("arguments", {})
    edited = "; it was edited or not written by signorini: start a new run (--overwrite)"
    if not isinstance(stored, dict):
        raise ValueError(f"{file}: its arguments are not a JSON object{edited}")
    for key, value in stored.items():
        kind = _KINDS.get(LEGACY_KEYS.get(key, key))
        if kind is None:
            raise ValueError(f"{file} records an unknown argument {key!r}{edited}")
        if not _is_kind(value, kind):
            name = LEGACY_KEYS.get(key, key)
            raise ValueError(
                f"{file} records {key} = {json.dumps(value)}, which {flag(name)} never "
                f"takes ({_KIND_TEXT[kind]}){edited}"
            )
    return dict(stored)


def resumed_settings(args: argparse.Namespace, stored: Mapping[str, object]) -> RunSettings:
    """The settings an interrupted run recorded (``stored``, its manifest's ``arguments``,
    also as written before the options had their present names); flags given again must
    agree with them.

    Raises
    ------
    ValueError
        Listing every flag given with another value than the run's.
    """
    options = _checked(AdaptiveOptions.from_record, stored)
    record = {**options.to_record(), **{name: stored.get(name, False) for name in FILE_FLAGS}}
    conflicts = []
    for dest in (*OPTION_FLAGS, *FILE_FLAGS):
        given = _given(args, dest)
        old = record[OPTION_FLAGS.get(dest, dest)]
        if given is not None and given != old:
            value = "" if isinstance(given, bool) else f" {given}"
            conflicts.append(f"--{dest.replace('_', '-')}{value} (the run has {old})")
    if conflicts:
        raise ValueError(
            f"--resume {args.resume}: {', '.join(conflicts)}; leave these options out to "
            "continue the run, or start a new run with --overwrite"
        )
    return RunSettings(options, **{name: record[name] for name in FILE_FLAGS})
