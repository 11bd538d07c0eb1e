"""Writing result and record files whole or not at all.

A run can be killed at any moment (Ctrl-C, a session's end, a full disk). A reader of its files (the
validation report, `fdmRun --resume`, a notebook) must then find either the previous file or the new
one, never half of one: every file is written to `<path>.tmp` and renamed over `path`, which POSIX
makes atomic on one file system.
"""
from __future__ import annotations

import json
import os


def write_atomically(path: str, data: str | bytes) -> None:
    """Write `data` (str or bytes) to `path` whole or not at all: a temporary file renamed over it."""
    tmp = path + ".tmp"
    with open(tmp, "wb" if isinstance(data, bytes) else "w") as f:
        f.write(data)
    os.replace(tmp, path)


def write_json(path: str, obj, indent: int | None = 1, **dump_options) -> None:
    """`obj` as JSON in `path`, whole or not at all; its folder is made if missing.

    `dump_options` go to json.dumps (e.g. `default=` for numpy values)."""
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    write_atomically(path, json.dumps(obj, indent=indent, **dump_options))


def relative_paths(obj, start: str | None = None):
    """A copy of `obj` (dicts, lists, strings) with every absolute path in it written relative to `start`
    (default: the working directory, from which the command recorded beside it was given). Summaries that
    may be shipped (docs/data/) name no folder of the machine they were made on (tests/test_docs.py)."""
    start = os.getcwd() if start is None else start
    if isinstance(obj, dict):
        return {k: relative_paths(v, start) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [relative_paths(v, start) for v in obj]
    if isinstance(obj, str) and os.path.isabs(obj) and not any(c.isspace() for c in obj):
        return os.path.relpath(obj, start)
    return obj
