"""The answers given to the checks, as data that another process can check again.

When the environment variable `ANSWERS_ENV` names a file (the grader of
``python -m coursekit grade`` sets it for the kernel of each submission), every
call of a course ``check_*`` appends one JSON line to it the moment it is made::

    {"check": "check_msd_state_space", "args": {"A": ..., "B": ..., "C": ...}}

`encode` turns an answer into JSON that stands for data only (numbers, lists,
arrays, complex numbers, strings, sympy matrices, dicts); `decode` rebuilds
an equal answer without ever running code from the file (no pickle, no eval),
so a file the student's kernel could write to cannot run code in the grading
process. A function given as an answer (``check_pendulum_f(f)``) cannot be
carried over: it is recorded as the calls the check made to it and what each
returned (`Tape`), and `decode` rebuilds a function that replays them
(`Replay`), so the grader's check sees the same values the student's did.
Anything else (a widget, a file handle) is recorded by its type name only and
comes back as an object of that name, which the checks reject as they did in
the notebook.
"""

from __future__ import annotations

import json
import numbers
import os
from typing import Any

import numpy as np

__all__ = ["ANSWERS_ENV", "MAX_ITEMS", "Tape", "Replay", "encode", "decode", "append_record",
           "read_records"]

#: the environment variable naming the file the answers are appended to
ANSWERS_ENV = "COURSEKIT_ANSWERS_FILE"

#: numbers and entries one answer may hold; beyond that it is recorded by its type name only
MAX_ITEMS = 100_000

#: records and bytes read back from one answers file at most (a notebook could write without end)
MAX_RECORDS = 10_000
MAX_BYTES = 64 * 2**20


class _Budget:
    """How many more items an answer may hold while it is being encoded."""

    def __init__(self, items: int = MAX_ITEMS):
        self.items = items

    def take(self, count: int) -> bool:
        self.items -= count
        return self.items >= 0


def _is_sympy(value) -> bool:
    return type(value).__module__.split(".")[0] == "sympy"


def _number(value) -> Any:
    """A Python number as JSON (complex numbers as {"complex": [re, im]})."""
    if isinstance(value, bool):
        return bool(value)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    return {"complex": [float(value.real), float(value.imag)]}


def _encode_array(value, budget: _Budget) -> Any:
    if not budget.take(int(value.size)):
        return {"opaque": type(value).__name__}
    if value.dtype.kind in "biufc":
        flat = [_number(v) for v in value.ravel().tolist()]
        return {"ndarray": flat, "shape": list(value.shape), "kind": value.dtype.kind}
    return {"objects": [_encode(v, budget) for v in value.ravel().tolist()], "shape": list(value.shape)}


def _encode_sympy(value, budget: _Budget) -> Any:
    if hasattr(value, "tolist") and hasattr(value, "shape"):     # a sympy Matrix
        if not budget.take(len(value)):
            return {"opaque": type(value).__name__}
        return {"sympy_matrix": [[_encode_sympy(v, budget) for v in row] for row in value.tolist()]}
    if str(value) in ("True", "False"):
        return {"sympy_bool": str(value) == "True"}
    if getattr(value, "is_number", False):
        try:
            return _number(complex(value)) if not getattr(value, "is_real", False) else float(value)
        except (TypeError, ValueError):
            pass
    return {"sympy_symbol": str(value)[:200]}


def _encode(value, budget: _Budget) -> Any:
    if value is None or isinstance(value, str):
        return value if value is None or budget.take(len(value) // 100 + 1) else {"opaque": "str"}
    if isinstance(value, np.generic) and value.dtype.kind in "biufc":
        return _number(value.item())                   # np.False_, np.int64(2), ... as numbers
    if isinstance(value, numbers.Number) and not _is_sympy(value):
        return _number(value)
    if _is_sympy(value):
        return _encode_sympy(value, budget)
    if isinstance(value, np.ndarray):
        return _encode_array(value, budget)
    if isinstance(value, (list, tuple)) and budget.take(len(value)):
        items = [_encode(v, budget) for v in value]
        return items if isinstance(value, list) else {"tuple": items}
    if isinstance(value, dict) and budget.take(len(value)):
        return {"dict": [[_encode(k, budget), _encode(v, budget)] for k, v in value.items()]}
    if value is Ellipsis:
        return {"ellipsis": True}
    if isinstance(value, bytes):
        return {"bytes": value[:200].decode("latin-1")}
    if isinstance(value, Tape):
        return {"function": value.name, "calls": value.calls}
    return {"opaque": type(value).__name__}


def encode(value) -> Any:
    """`value` as JSON data (see the module docstring); large answers by their type name only."""
    return _encode(value, _Budget())


class Tape:
    """Stands for a student's function during a check: calls it and notes each call and result."""

    def __init__(self, function):
        self.function = function
        self.name = getattr(function, "__name__", "function")
        self.calls: list[dict] = []

    def __call__(self, *args):
        entry = {"args": encode(list(args))}
        self.calls.append(entry)
        try:
            result = self.function(*args)
        except Exception as error:  # noted, then raised again for the check to report
            entry["raised"] = [type(error).__name__, str(error)[:500]]
            raise
        entry["returned"] = encode(result)
        return result


class Replay:
    """A function that answers the calls noted by a `Tape`, in the grading process."""

    def __init__(self, name: str, calls: list):
        self.__name__ = str(name)
        self.calls = calls if isinstance(calls, list) else []

    def __call__(self, *args):
        wanted = encode(list(args))
        for entry in self.calls:
            if isinstance(entry, dict) and entry.get("args") == wanted:
                if "raised" in entry:
                    raise _exception(entry["raised"])
                return decode(entry.get("returned"))
        raise LookupError(f"{self.__name__} was not called with these arguments in the notebook")


def _exception(raised) -> Exception:
    """An exception of the recorded name and message (a class made here, never imported)."""
    name, message = (list(raised) + ["Exception", ""])[:2] if isinstance(raised, list) else ("Exception", "")
    kind = type(str(name) if str(name).isidentifier() else "Exception", (Exception,), {})
    return kind(str(message))


def _opaque(name) -> object:
    """An object whose type has the recorded name (the checks name the type in their message)."""
    name = str(name) if str(name).isidentifier() else "object"
    return type(name, (), {"__repr__": lambda self: f"<{name}>"})()


def _decode_array(data: dict):
    kind = {"b": bool, "i": int, "u": int, "f": float, "c": complex}.get(data.get("kind"), float)
    flat = [decode(v) for v in data.get("ndarray", [])]
    return np.array(flat, dtype=kind).reshape([int(n) for n in data.get("shape", [len(flat)])])


def _decode_objects(data: dict):
    flat = [decode(v) for v in data.get("objects", [])]
    out = np.empty(len(flat), dtype=object)
    out[:] = flat
    return out.reshape([int(n) for n in data.get("shape", [len(flat)])])


def _decode_sympy_matrix(rows):
    import sympy
    return sympy.Matrix([[decode(v) for v in row] for row in rows])


def _decode_dict(data: dict) -> Any:
    import sympy
    decoders = {
        "complex": lambda v: complex(*v),
        "ndarray": lambda _: _decode_array(data),
        "objects": lambda _: _decode_objects(data),
        "tuple": lambda v: tuple(decode(x) for x in v),
        "dict": lambda v: {_hashable(decode(k)): decode(x) for k, x in v},
        "sympy_matrix": _decode_sympy_matrix,
        "sympy_bool": lambda v: sympy.true if v else sympy.false,
        "sympy_symbol": lambda v: sympy.Symbol(str(v)),
        "ellipsis": lambda _: Ellipsis,
        "bytes": lambda v: str(v).encode("latin-1"),
        "function": lambda v: Replay(v, data.get("calls", [])),
        "opaque": _opaque,
    }
    for key, decoder in decoders.items():
        if key in data:
            return decoder(data[key])
    return _opaque("object")


def _hashable(value):
    try:
        hash(value)
    except TypeError:
        return repr(value)
    return value


def decode(data: Any) -> Any:
    """The answer `data` stands for (the inverse of `encode`); builds data, never runs code."""
    if isinstance(data, list):
        return [decode(v) for v in data]
    if isinstance(data, dict):
        return _decode_dict(data)
    return data


def append_record(check: str, arguments: dict) -> None:
    """Append one answer to the file named by `ANSWERS_ENV` (nothing when it is unset)."""
    path = os.environ.get(ANSWERS_ENV)
    if not path:
        return
    line = json.dumps({"check": check, "args": {k: encode(v) for k, v in arguments.items()}})
    with open(path, "a", encoding="utf-8") as file:
        file.write(line + "\n")
        file.flush()


def read_records(source) -> list[dict]:
    """The well-formed records of an answers file, in order (unreadable lines are skipped).

    `source` is a path, or a file opened for reading (the grader keeps the file
    open while the notebook runs, so it still reads it if the notebook deletes it).
    """
    try:
        if hasattr(source, "read"):
            text = source.read(MAX_BYTES)
        else:
            with open(source, encoding="utf-8", errors="replace") as file:
                text = file.read(MAX_BYTES)
    except (OSError, ValueError):
        return []
    records = []
    for line in text.splitlines()[:MAX_RECORDS]:
        try:
            record = json.loads(line)
        except (ValueError, RecursionError):
            continue
        if (isinstance(record, dict) and isinstance(record.get("check"), str)
                and isinstance(record.get("args"), dict)):
            records.append(record)
    return records
