"""Argument checks shared by the package's modules: each argument converted to what the extension
module takes, TypeError naming the argument for a wrong type; ranges are the library's to check."""
from __future__ import annotations

import errno
import numbers
import os
from typing import Iterable

import numpy as np

def _signal(name: str, x, ndim: int) -> np.ndarray:
    """An argument as float64 in C order: float64 C-ordered arrays as they are (no copy), other
    real numbers converted once; TypeError for anything else, ValueError for the wrong shape."""
    a = np.asarray(x)
    if a.dtype.kind not in "biuf":
        raise TypeError(f"{name}: expected real numbers (float64), got dtype {a.dtype}")
    if a.ndim != ndim:
        shape = "(samples,)" if ndim == 1 else "(channels, samples)"
        raise ValueError(f"{name} must be {ndim}-D {shape}, not {a.ndim}-D")
    return np.ascontiguousarray(a, dtype=np.float64)


def _kind(v) -> str:
    return type(v).__name__


def _real(name: str, v) -> float:
    """A real number argument (int, float, numpy scalar; not bool, not text): TypeError
    otherwise. Its range is the library's to check, with the CLI's message."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real):
        raise TypeError(f"{name}: expected a number, got {_kind(v)} {v!r}")
    return float(v)


def _integer(name: str, v) -> int:
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Integral):
        raise TypeError(f"{name}: expected a whole number, got {_kind(v)} {v!r}")
    return int(v)


def _flag(name: str, v) -> bool:
    if not isinstance(v, (bool, np.bool_)):
        raise TypeError(f"{name}: expected True or False, got {_kind(v)} {v!r}")
    return bool(v)


def _text(name: str, v) -> str:
    if not isinstance(v, str):
        raise TypeError(f"{name}: expected a string, got {_kind(v)} {v!r}")
    return v


def _names(name: str, v) -> list:
    """A list of names: a sequence of strings, or one string of comma-separated names as the
    CLI takes them ("force1,acc1"); None is the empty list."""
    if v is None:
        return []
    if isinstance(v, str):
        return [n.strip() for n in v.split(",")] if v else []
    if not isinstance(v, Iterable) or isinstance(v, (bytes, dict)):
        raise TypeError(f"{name}: expected names (a list of strings or \"a,b\"), got {_kind(v)}")
    out = list(v)
    for n in out:
        if not isinstance(n, str):
            raise TypeError(f"{name}: expected names (strings), got {_kind(n)} {n!r}")
    return out


def _reals(name: str, v) -> list:
    if isinstance(v, (str, bytes)) or not isinstance(v, Iterable):
        raise TypeError(f"{name}: expected a sequence of numbers, got {_kind(v)} {v!r}")
    return [_real(f"{name}[{i}]", x) for i, x in enumerate(v)]


def _counted(name: str, v, what: str) -> list:
    """Numbers of a chain's elements (masses, springs...), each named as the library names it,
    counted from 1 ("masses_kg: mass 2: expected a number, got str '1'"); their values are the
    library's to check."""
    if isinstance(v, (str, bytes)) or not isinstance(v, Iterable):
        raise TypeError(f"{name}: expected a sequence of numbers, got {_kind(v)} {v!r}")
    return [_real(f"{name}: {what} {i}", x) for i, x in enumerate(v, start=1)]


def _input_path(name: str, p) -> str:
    """A file argument: a path (str or os.PathLike) to a file that is there; TypeError for
    anything else, FileNotFoundError (as open() raises) for a path with nothing at it."""
    if not isinstance(p, (str, os.PathLike)):
        raise TypeError(f"{name}: expected a file path, got {_kind(p)}")
    path = os.fspath(p)
    if not isinstance(path, str):
        raise TypeError(f"{name}: expected a file path as text, got {_kind(path)}")
    if not os.path.exists(path):
        raise FileNotFoundError(errno.ENOENT, f"{name}: no such file", path)
    return path


def _output_path(name: str, p) -> str:
    """A file to write: its folder must be there (FileNotFoundError otherwise)."""
    if not isinstance(p, (str, os.PathLike)):
        raise TypeError(f"{name}: expected a file path, got {_kind(p)}")
    path = os.fspath(p)
    folder = os.path.dirname(path) or "."
    if not os.path.isdir(folder):
        raise FileNotFoundError(errno.ENOENT, f"{name}: no such folder", folder)
    return path


def _repr(name: str, **fields) -> str:
    def short(v):
        if isinstance(v, np.ndarray):
            return f"array{v.shape}" if v.size > 6 else np.array2string(v, precision=6)
        return repr(v)
    return name + "(" + ", ".join(f"{k}={short(v)}" for k, v in fields.items()) + ")"
