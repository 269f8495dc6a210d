"""The answers given to the checks, as data that another process can check again.

When the environment variable `ANSWERS_ENV` names a file (the grader of
``python -m coursekit grade`` sets it for the kernel of each submission), every
call of a course ``check_*`` appends one JSON line to it the moment it is made::

    {"check": "check_msd_state_space", "args": {"A": ..., "B": ..., "C": ...}}

`encode` turns an answer into JSON that stands for data only (numbers, lists,
arrays, complex numbers, strings, sympy matrices, dicts). It never raises and
never changes the answer the check then sees: whatever it cannot write as
data is recorded by its type name. An array-like value (``np.matrix``, or an
object with ``__array__`` such as a pandas frame) is recorded as the numbers
``np.asarray`` gives, which is what the checks compare.

The file is written by code the grader does not trust, so reading it back is
bounded and runs no code:

* `read_last_records` reads the file once, line by line (lines longer than
  `MAX_LINE` are skipped unread), and keeps the last well-formed record of
  each check however many come before it;
* `decode` rebuilds an answer from the JSON types and the known shapes
  below only: numbers, strings (always as strings: never parsed, never
  handed to sympy), lists, tuples, dicts, numeric arrays, sympy matrices
  of numbers and symbols, a replayed function, or an `Opaque` stand-in.
  Anything else becomes an `Opaque`. Its cost is linear in the size of the
  record: every JSON value is visited once, at most `MAX_ITEMS` of them,
  and no class is made per value.

A function given as an answer (``check_pendulum_f(f)``) cannot be carried
over: it is recorded as the calls the check made to it and what each
returned (`Tape`), and `decode` rebuilds a function that replays them
(`Replay`), so the grader's check sees the same values the student's did.
"""

from __future__ import annotations

import json
import numbers
import os
from functools import lru_cache
from typing import Any, Iterable

import numpy as np

__all__ = ["ANSWERS_ENV", "MAX_ITEMS", "MAX_LINE", "Tape", "Replay", "Opaque", "encode", "decode",
           "append_record", "read_last_records"]

#: the environment variable naming the file the answers are appended to
ANSWERS_ENV = "COURSEKIT_ANSWERS_FILE"

#: numbers and entries one answer may hold; beyond that it is recorded (or decoded) by its type name only
MAX_ITEMS = 100_000

#: characters of one record line at most; a longer line is skipped when the file is read back
MAX_LINE = 32 * 2**20


class _Budget:
    """How many more items an answer may hold while it is encoded or decoded."""

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


def _encode_array(value: np.ndarray, budget: _Budget) -> Any:
    value = np.asarray(value)                        # np.matrix stays 2-D on ravel(): take the plain array
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


def _array_like(value) -> np.ndarray | None:
    """The numbers of an object that offers ``__array__`` (pandas, xarray), or None."""
    if isinstance(value, (np.ndarray, np.generic)) or not hasattr(value, "__array__"):
        return None
    try:
        array = np.asarray(value)
    except Exception:  # its own conversion failed: recorded by type name, as any other object
        return None
    return array if array.dtype.kind in "biufc" else None


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
    array = _array_like(value)
    if array is not None:
        return _encode_array(array, budget)
    return {"opaque": type(value).__name__}


def encode(value) -> Any:
    """`value` as JSON data (see the module docstring); never raises, never changes `value`.

    Large answers, and anything that cannot be read as data without running
    more than its own conversion to an array, are recorded by type name only.
    """
    try:
        return _encode(value, _Budget())
    except Exception:  # an answer the recorder cannot read must not disturb the check
        return {"opaque": type(value).__name__}


class Tape:
    """Stands for a student's function during a check: calls it and notes each call and result.

    The check sees exactly what the function returns or raises; the notes are
    taken with `encode`, which never raises.
    """

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


def _recorded_name(name) -> str:
    """A recorded type name fit to name a class here (an identifier of at most 100 characters)."""
    return name if isinstance(name, str) and name.isidentifier() and len(name) <= 100 else "object"


@lru_cache(maxsize=256)
def _named_class(name: str, base: type) -> type:
    """One class per recorded name (cached: a record of many objects makes few classes)."""
    return type(name, (base,), {"__module__": __name__})


class Opaque:
    """Stands for an answer recorded by its type name only; `type(x).__name__` is that name."""

    def __repr__(self) -> str:
        return f"<{type(self).__name__}>"


def _opaque(name) -> Opaque:
    return _named_class(_recorded_name(name), Opaque)()


def _exception(raised) -> Exception:
    """An exception of the recorded name and message (a class made here, never imported)."""
    name, message = (list(raised) + ["Exception", ""])[:2] if isinstance(raised, list) else ("Exception", "")
    return _named_class(_recorded_name(name) if name != "object" else "Exception", Exception)(str(message)[:500])


_KINDS = {"b": bool, "i": int, "u": int, "f": float, "c": complex}


def _shape(data: dict, size: int) -> list[int] | None:
    """The recorded shape when it is a list of whole numbers that fits `size` entries, else None."""
    shape = data.get("shape", [size])
    if not (isinstance(shape, list) and len(shape) <= 32
            and all(isinstance(n, int) and not isinstance(n, bool) and n >= 0 for n in shape)):
        return None
    return shape if int(np.prod(shape, dtype=object)) == size else None


def _decode_array(data: dict, budget: _Budget):
    flat, kind = data.get("ndarray"), _KINDS.get(data.get("kind"), float)
    if not isinstance(flat, list) or not budget.take(len(flat)):
        return _opaque("ndarray")
    values = [_decode_number(v) for v in flat]
    shape = _shape(data, len(values))
    if shape is None or any(v is None for v in values):
        return _opaque("ndarray")
    if kind is not complex and any(isinstance(v, complex) for v in values):
        return _opaque("ndarray")
    try:
        return np.array(values, dtype=kind).reshape(shape)
    except (OverflowError, ValueError, TypeError):   # an integer too large for int64, say
        return _opaque("ndarray")


def _decode_objects(data: dict, budget: _Budget):
    flat = data.get("objects")
    if not isinstance(flat, list) or not budget.take(len(flat)):
        return _opaque("ndarray")
    shape = _shape(data, len(flat))
    if shape is None:
        return _opaque("ndarray")
    out = np.empty(len(flat), dtype=object)
    out[:] = [_decode(v, budget) for v in flat]
    return out.reshape(shape)


def _decode_number(value) -> Any:
    """A number from its JSON form (int, float, bool, {"complex": [re, im]}), else None."""
    if isinstance(value, (bool, int, float)):
        return value
    if isinstance(value, dict) and len(value) == 1:
        parts = value.get("complex")
        if isinstance(parts, list) and len(parts) == 2 and all(
                isinstance(p, (int, float)) and not isinstance(p, bool) for p in parts):
            return complex(parts[0], parts[1])
    return None


def _decode_sympy_entry(value, budget: _Budget):
    """One entry of a sympy matrix: a number or a sympy symbol, else None (never a string)."""
    number = _decode_number(value)
    if number is not None:
        return number
    if isinstance(value, dict) and isinstance(value.get("sympy_symbol"), str):
        return _decode(value, budget)
    return None


def _decode_sympy_matrix(rows, budget: _Budget):
    """A sympy Matrix of numbers and symbols; other entries (text above all: sympy would parse
    it as code) make the answer an `Opaque` named after the matrix."""
    import sympy
    if not (isinstance(rows, list) and rows and all(isinstance(row, list) for row in rows)
            and len({len(row) for row in rows}) == 1 and budget.take(sum(len(row) for row in rows))):
        return _opaque("MutableDenseMatrix")
    entries = [[_decode_sympy_entry(v, budget) for v in row] for row in rows]
    if any(v is None for row in entries for v in row):
        return _opaque("MutableDenseMatrix")
    return sympy.Matrix(entries)


def _decode_dict(data: dict, budget: _Budget) -> Any:
    """The known shapes of `encode`, keyed by their one tag; anything else is an `Opaque`."""
    import sympy
    tags = [key for key in _DECODERS if key in data]
    if not tags:
        return _opaque("object")
    tag = tags[0]
    value = data[tag]
    if tag == "complex":
        number = _decode_number({"complex": value})
        return _opaque("complex") if number is None else number
    if tag == "ndarray":
        return _decode_array(data, budget)
    if tag == "objects":
        return _decode_objects(data, budget)
    if tag == "sympy_matrix":
        return _decode_sympy_matrix(value, budget)
    if tag in ("tuple", "dict") and not isinstance(value, list):
        return _opaque(tag)
    if tag == "tuple":
        return tuple(_decode(v, budget) for v in value)
    if tag == "dict":
        pairs = [pair for pair in value if isinstance(pair, list) and len(pair) == 2]
        return {_hashable(_decode(k, budget)): _decode(v, budget) for k, v in pairs}
    if tag == "sympy_bool":
        return sympy.true if value is True else sympy.false
    if tag == "sympy_symbol":
        return sympy.Symbol(str(value)[:200]) if isinstance(value, str) and value else _opaque("Symbol")
    if tag == "bytes":
        return value[:200].encode("latin-1", "replace") if isinstance(value, str) else _opaque("bytes")
    if tag == "function":
        return Replay(str(value)[:100], data.get("calls", []))
    if tag == "ellipsis":
        return Ellipsis
    return _opaque(value)


#: the tags `encode` writes, in the order `decode` looks for them
_DECODERS = ("complex", "ndarray", "objects", "tuple", "dict", "sympy_matrix", "sympy_bool", "sympy_symbol",
             "ellipsis", "bytes", "function", "opaque")


def _hashable(value):
    try:
        hash(value)
    except TypeError:
        return repr(value)[:200]
    return value


def _decode(data: Any, budget: _Budget) -> Any:
    if not budget.take(1):
        return _opaque("object")
    if isinstance(data, list):
        return [_decode(v, budget) for v in data]
    if isinstance(data, dict):
        return _decode_dict(data, budget)
    if data is None or isinstance(data, (bool, int, float, str)):
        return data
    return _opaque("object")


def decode(data: Any) -> Any:
    """The answer `data` stands for (the inverse of `encode`): data only, never code.

    At most `MAX_ITEMS` values are decoded; past that, and for anything not of
    a known shape, the value is an `Opaque` (which the checks reject by name).
    Never raises for any JSON input (a nesting too deep for Python is an `Opaque`).
    """
    try:
        return _decode(data, _Budget(2 * MAX_ITEMS))
    except RecursionError:
        return _opaque("object")


def append_record(check: str, arguments: dict) -> None:
    """Append one answer to the file named by `ANSWERS_ENV` (nothing when it is unset)."""
    path = os.environ.get(ANSWERS_ENV)
    if not path:
        return
    line = json.dumps({"check": check, "args": {k: encode(v) for k, v in arguments.items()}})
    with open(path, "a", encoding="utf-8") as file:
        file.write(line + "\n")
        file.flush()


def _lines(file) -> Iterable[str]:
    """The lines of `file` of at most `MAX_LINE` characters; longer ones are skipped unread."""
    while True:
        line = file.readline(MAX_LINE + 1)
        if not line:
            return
        if len(line) > MAX_LINE and not line.endswith("\n"):
            while (rest := file.readline(MAX_LINE)) and not rest.endswith("\n"):
                pass
            continue
        yield line


def _record(line: str, checks: frozenset | None) -> dict | None:
    """The record a line holds when it is well formed (and of one of `checks`), else None."""
    try:
        record = json.loads(line)
    except (ValueError, RecursionError):
        return None
    if not (isinstance(record, dict) and isinstance(record.get("check"), str)
            and isinstance(record.get("args"), dict)):
        return None
    if checks is not None and record["check"] not in checks:
        return None
    return {"check": record["check"], "args": record["args"]}


def read_last_records(source, checks: Iterable[str] | None = None) -> dict[str, dict]:
    """The last well-formed record of each check in an answers file: ``{check: args}``.

    `source` is a path, or a file opened for reading (the grader keeps the file
    open while the notebook runs, so it still reads it if the notebook deletes
    it). Only records of `checks` are kept when given. The file is read once,
    in lines of at most `MAX_LINE` characters, and only the last record of each
    check is held, so the cost is linear in the file's size and the memory
    bounded by `MAX_LINE` per check. An unreadable file has no records.
    """
    wanted = None if checks is None else frozenset(checks)
    last: dict[str, dict] = {}
    try:
        if hasattr(source, "read"):
            for line in _lines(source):
                if (record := _record(line, wanted)) is not None:
                    last[record["check"]] = record["args"]
        else:
            with open(source, encoding="utf-8", errors="replace") as file:
                return read_last_records(file, checks)
    except (OSError, ValueError):
        return last
    return last
