"""Modes of a hammer test fitted to its FRFs (``vibid modes``): LSCF, LSCE, rational fit or
peaks, with their intervals and the stabilization diagram."""
from __future__ import annotations

import dataclasses
from typing import Optional

import numpy as np

from . import _vibid
from ._checks import _input_path, _names, _repr
from .estimation import FrfEstimate, _estimation_options, frf_estimate
from .model import Frd
from .recording import Recording

@dataclasses.dataclass(repr=False)
class Modes:
    """``vibid modes --json`` as arrays: per mode freq_hz, omega_rad_s, zeta, ratio (a1/a2),
    shapes (one column per mode), 95 % intervals in ``ci95`` ([lo, hi] per quantity and mode,
    NaN where none could be estimated); ``stabilization`` holds the diagram's poles as arrays
    (order, freq_hz, zeta, stable_freq, stable_damping, stable_shape, cluster). ``json`` is the
    CLI's JSON object."""
    freq_hz: np.ndarray
    omega_rad_s: np.ndarray
    zeta: np.ndarray
    ratio: np.ndarray
    shapes: np.ndarray
    ci95: dict
    stabilization: Optional[dict]
    method: str
    warnings: list
    json: dict

    def __repr__(self) -> str:
        return _repr("Modes", method=self.method, freq_hz=self.freq_hz, zeta=self.zeta,
                     ratio=self.ratio)


def _num(v):
    return np.nan if v is None else float(v)


def _modes(j: dict) -> Modes:
    ms = j["modes"]
    ci = {}
    for q in ("omega_rad_s", "zeta", "ratio"):
        ci[q] = np.array([[np.nan, np.nan] if (m.get("ci95") or {}).get(q) is None
                          else m["ci95"][q] for m in ms], dtype=float).reshape(-1, 2)
    stab = None
    if "stabilization" in j:
        poles = j["stabilization"]["poles"]
        stab = {k: np.array([p[k] for p in poles]) for k in
                ("order", "freq_hz", "zeta", "stable_freq", "stable_damping", "stable_shape",
                 "cluster")}
        stab["band_hz"] = tuple(j["stabilization"]["band_hz"])
        stab["selected"] = j["stabilization"]["selected"]
    return Modes(freq_hz=np.array([m["freq_hz"] for m in ms], dtype=float),
                 omega_rad_s=np.array([m["omega_rad_s"] for m in ms], dtype=float),
                 zeta=np.array([m["zeta"] for m in ms], dtype=float),
                 ratio=np.array([_num(m.get("ratio")) for m in ms], dtype=float),
                 shapes=np.array([m["shape"] for m in ms], dtype=float).T, ci95=ci,
                 stabilization=stab, method=j["method"], warnings=list(j["warnings"]), json=j)


def modes(inputs, method: str = "lscf", orders: str = "", driving_point: str = "",
          fmin_hz: Optional[float] = None, fmax_hz: Optional[float] = None,
          force: str = "", responses="", **options) -> Modes:
    """Modes of one hammer test (``vibid modes``): method lscf, lsce, fit or peaks; orders
    "MIN:MAX[:STEP]"; the driving point by column name or 1-based index (default: the last
    response). ``inputs``: FRF files or recordings (estimated first with ``frf_estimate``'s
    options), or FRFs in memory (a FrfEstimate, an Frd, or a list of them: a receptance shaped
    (n_out, 1, n_freq)); several inputs are joined as responses."""
    listed = list(inputs) if isinstance(inputs, (list, tuple)) else [inputs]
    recordings = [x for x in listed if isinstance(x, Recording)]
    if recordings:
        # Recordings in memory: estimated as frf_estimate estimates them (the board's sampling
        # instants included), then their FRFs' modes, as `vibid modes` on the files.
        if len(recordings) != len(listed):
            raise TypeError("modes: give either recordings in memory or files/FRFs, not both")
        return modes([frf_estimate(r, force=force, responses=responses, **options)
                      for r in recordings], method, orders, driving_point, fmin_hz, fmax_hz)
    in_memory = [x for x in listed if isinstance(x, (Frd, FrfEstimate))]
    if in_memory:
        if len(in_memory) != (len(inputs) if isinstance(inputs, (list, tuple)) else 1):
            raise TypeError("modes: give either files or FRFs in memory, not both")
        if options or force or responses:
            raise TypeError("modes of FRFs in memory take no estimation options: "
                            "estimate with frf_estimate first")
        # One estimate's ring-downs: the amplitude check `vibid modes` makes on its recording.
        ringdowns = (in_memory[0]._ringdowns if len(in_memory) == 1 and
                     isinstance(in_memory[0], FrfEstimate) else None)
        return _modes(_vibid.modes_of([_library_frf(x) for x in in_memory],
                                      [f"frf {i + 1}" for i in range(len(in_memory))],
                                      _mode_request(method, orders, driving_point, fmin_hz,
                                                    fmax_hz), ringdowns))
    paths = [_input_path("inputs", p) for p in listed]
    names = ",".join(_names("responses", responses))
    o = _estimation_options(force=force, responses=names, **options)
    return _modes(_vibid.modes(paths, o, _mode_request(method, orders, driving_point, fmin_hz,
                                                       fmax_hz)))


def _mode_request(method, orders, driving_point, fmin_hz, fmax_hz):
    r = _vibid._ModeRequest()
    r.method, r.orders, r.driving_point = method, orders, str(driving_point)
    if fmin_hz is not None:
        r.fmin_hz = fmin_hz
    if fmax_hz is not None:
        r.fmax_hz = fmax_hz
    return r


def _library_frf(x):
    """The library's FRF of a FrfEstimate or Frd: its own when vibid estimated it, else one built
    from the arrays (one input)."""
    frd = x.frd if isinstance(x, FrfEstimate) else x
    if frd._frf is not None:
        return frd._frf
    h = np.asarray(frd.h)
    if h.ndim != 3 or h.shape[1] != 1:
        raise ValueError(f"an Frd's h must be shaped (n_out, 1, n_freq), not {h.shape}")
    coherence = None if frd.coherence is None else np.ascontiguousarray(
        np.asarray(frd.coherence, dtype=float)[:, 0, :].T)
    return _vibid.frf_from_arrays(np.asarray(frd.freq_hz, dtype=float),
                                  np.ascontiguousarray(h[:, 0, :].T.astype(complex)), coherence,
                                  frd.kind, [str(o) for o in frd.outputs], str(frd.inputs[0]))
