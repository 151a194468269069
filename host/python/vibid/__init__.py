"""vibid: identification of mass-spring vibration rigs and the board's disturbance observer.

The functions mirror the ``vibid`` command line (``vibid.modal`` does what ``vibid modal`` does,
with the same defaults) and call the same C++ library. Units are SI and named in every field
(``freq_hz``, ``omega_rad_s``, ``m_kg``...). Arrays are float64; a recording's ``data`` is shaped
(channels, samples); an FRF's ``h`` is shaped (n_out, n_in, n_freq) beside its ``freq_hz``, as
python-control's FRD. Bad input raises ValueError with the CLI's message, an argument of the
wrong type TypeError, a file that is not there FileNotFoundError; board errors raise
vibid.DeviceError.
"""
from __future__ import annotations

import dataclasses
import errno
import math
import numbers
import os
from typing import Iterable, Iterator, Optional, Sequence

import numpy as np

from . import _vibid
from ._vibid import DeviceError, NumericalError

__all__ = [
    "DeviceError", "Model", "load_model", "modal", "Modal", "frf", "Frd", "simulate",
    "Simulation", "Recording", "read_recording", "Board", "list_devices", "frf_estimate",
    "FrfEstimate", "Hit", "modes", "Modes", "identify", "Identification", "default_segment",
    "frf_estimate_arrays", "dob_design", "ObserverDesign", "dob_run", "ObserverRun", "lowpass",
    "dob_compare", "Agreement", "decay", "Decay", "NumericalError", "SysidModel", "arx", "pem",
    "tfest", "compare", "Comparison", "report", "watch", "Watch", "WatchSession", "WatchBlock",
    "WatchMode", "WatchReference", "LiveWatch", "ssi_cov", "OmaModes",
]


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


def _finite(name: str, values) -> list:
    """Numbers for a model file: every one finite (a JSON model cannot hold NaN or inf)."""
    out = _reals(name, values)
    for i, x in enumerate(out):
        if not math.isfinite(x):
            raise ValueError(f"{name}[{i}] is {x}: every value must be a finite number")
    return out


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


def _model(name: str, m) -> "Model":
    if isinstance(m, Model):
        return m
    hint = (" (a model file: vibid.load_model(path))" if isinstance(m, (str, os.PathLike))
            else "")
    raise TypeError(f"{name}: expected a vibid.Model, got {_kind(m)}{hint}")


def _repr(name: str, **fields) -> str:
    def short(v):
        if isinstance(v, np.ndarray):
            return f"array{v.shape}" if v.size > 6 else np.array2string(v, precision=6)
        return repr(v)
    return name + "(" + ", ".join(f"{k}={short(v)}" for k, v in fields.items()) + ")"


# --- models -------------------------------------------------------------------------------------

class Model:
    """A lumped-parameter rig M x'' + C x' + K x = F: ``Model(m_kg, k_n_per_m, c_ns_per_m)``
    takes the matrices in kg, N/m and N*s/m (square, one row per DOF; C None: undamped); a 1-D
    ``m_kg`` is the diagonal of lumped masses. A chain from its masses and springs is
    ``Model.chain``."""

    def __init__(self, m_kg, k_n_per_m, c_ns_per_m=None):
        def matrix(name, x, diagonal_ok=False):
            a = np.asarray(x)
            if a.dtype.kind not in "biuf":
                raise TypeError(f"{name}: expected real numbers, got dtype {a.dtype}")
            a = a.astype(float)
            if a.ndim == 1 and diagonal_ok:
                a = np.diag(a)
            if a.ndim != 2 or a.shape[0] != a.shape[1]:
                chain = " (springs of a chain: Model.chain(masses_kg, springs_n_per_m))" \
                    if a.ndim == 1 else ""
                raise ValueError(f"{name} must be a square matrix (DOFs x DOFs), not shaped "
                                 f"{a.shape}{chain}")
            return a
        m = matrix("m_kg", m_kg, diagonal_ok=True)
        k = matrix("k_n_per_m", k_n_per_m)
        c = None if c_ns_per_m is None else matrix("c_ns_per_m", c_ns_per_m)
        self._m = _vibid._Model(m, k, c)

    @classmethod
    def _wrap(cls, m) -> "Model":
        self = cls.__new__(cls)
        self._m = m
        return self

    @classmethod
    def from_dict(cls, d: dict, source: str = "model") -> "Model":
        """From a model file's JSON object (chain, cart or M/K/C matrices)."""
        return cls._wrap(_vibid.model_from_dict(d, source))

    @classmethod
    def chain(cls, masses_kg, springs_n_per_m, dampers_ns_per_m=None) -> "Model":
        """Series chain ground -k1- m1 -k2- m2 ..., dashpots in parallel with the springs."""
        d = {"topology": "chain", "masses": _finite("masses_kg", masses_kg),
             "springs": _finite("springs_n_per_m", springs_n_per_m)}
        if dampers_ns_per_m is not None:
            d["dampers"] = _finite("dampers_ns_per_m", dampers_ns_per_m)
        return cls.from_dict(d)

    m_kg = property(lambda self: self._m.m_kg, doc="Mass matrix, kg.")
    c_ns_per_m = property(lambda self: self._m.c_ns_per_m, doc="Damping matrix, N*s/m.")
    k_n_per_m = property(lambda self: self._m.k_n_per_m, doc="Stiffness matrix, N/m.")
    dofs = property(lambda self: self._m.dofs, doc="Degrees of freedom.")

    def to_dict(self) -> dict:
        """The full-matrix model file form {"M", "C", "K"}."""
        return self._m.to_dict()

    def __repr__(self) -> str:
        return _repr("Model", dofs=self.dofs, m_kg=self.m_kg, k_n_per_m=self.k_n_per_m,
                     c_ns_per_m=self.c_ns_per_m)


def load_model(path: str) -> Model:
    """Reads a model file (JSON), as every ``vibid`` command taking MODEL.json does."""
    return Model._wrap(_vibid.load_model(_input_path("path", path)))


@dataclasses.dataclass(repr=False)
class Modal:
    """Modes in ascending frequency: ``vibid modal``'s table as arrays."""
    omega_rad_s: np.ndarray
    freq_hz: np.ndarray
    zeta: np.ndarray
    shapes: np.ndarray  #: mass-normalised, 1/sqrt(kg), one mode per column
    ratio: np.ndarray   #: a1/a2 per mode (NaN for one DOF)
    damping: str        #: none, proportional, general

    def __repr__(self) -> str:
        return _repr("Modal", freq_hz=self.freq_hz, zeta=self.zeta, ratio=self.ratio,
                     damping=self.damping)


def modal(model: Model) -> Modal:
    """Natural frequencies, damping ratios and mass-normalised shapes (``vibid modal``)."""
    return Modal(**_vibid.modal(_model("model", model)._m))


@dataclasses.dataclass(repr=False)
class Frd:
    """Frequency response data: ``h`` shaped (n_out, n_in, n_freq) at ``freq_hz``, as
    python-control's FRD (``control.frd(h, 2*pi*freq_hz)``)."""
    freq_hz: np.ndarray
    h: np.ndarray
    kind: str  #: receptance (m/N), mobility (m/(N*s)) or accelerance (m/(N*s^2))
    outputs: list
    inputs: list
    coherence: Optional[np.ndarray] = None  #: (n_out, n_in, n_freq) for estimated FRFs
    #: The library's own FRF when vibid estimated it (windows, pretrigger and level variance the
    #: modes' intervals use); None for one built from arrays.
    _frf: object = dataclasses.field(default=None, compare=False)

    @property
    def omega_rad_s(self) -> np.ndarray:
        return 2.0 * np.pi * self.freq_hz

    def __repr__(self) -> str:
        return _repr("Frd", kind=self.kind, shape=self.h.shape, outputs=self.outputs,
                     inputs=self.inputs, freq_hz=self.freq_hz)


def frf(model: Model, freq_hz, input: int = 1, outputs: Optional[Sequence[int]] = None,
        kind: str = "receptance") -> Frd:
    """The model's FRF (``vibid frf``): DOFs counted from 1; outputs default to every DOF."""
    model = _model("model", model)
    f = np.ascontiguousarray(freq_hz, dtype=float)
    outs = list(range(1, model.dofs + 1)) if outputs is None else list(outputs)
    for o in outs:
        if not 1 <= o <= model.dofs:
            raise ValueError(f"--output {o} is out of range 1..{model.dofs}")
    if not 1 <= input <= model.dofs:
        raise ValueError(f"--input {input} is out of range 1..{model.dofs}")
    omega = 2.0 * np.pi * f
    h = np.empty((len(outs), 1, f.size), dtype=complex)
    for i, o in enumerate(outs):
        h[i, 0, :] = _vibid.frf(model._m, input - 1, o - 1, kind, omega)
    return Frd(freq_hz=f, h=h, kind=kind, outputs=outs, inputs=[input])


@dataclasses.dataclass(repr=False)
class Simulation:
    """Samples at t_s; matrices have one row per sample and one column per DOF."""
    t_s: np.ndarray
    x_m: np.ndarray
    v_m_s: np.ndarray
    a_m_s2: np.ndarray
    force_n: np.ndarray

    def __repr__(self) -> str:
        return _repr("Simulation", samples=self.t_s.size, dofs=self.x_m.shape[1],
                     t_end_s=float(self.t_s[-1]))


def simulate(model: Model, dt_s: float, t_end_s: float, force: Iterable[str] = (),
             method: str = "rk4", x0_m=None, v0_m_s=None) -> Simulation:
    """Time simulation (``vibid simulate``): force SPECs as the CLI's --force
    (``halfsine:dof=2,amp=100,width=0.001``), method euler, rk4 or exact."""
    model = _model("model", model)
    forces = [force] if isinstance(force, str) else list(force)
    x0 = np.zeros(0) if x0_m is None else np.asarray(x0_m, dtype=float)
    v0 = np.zeros(0) if v0_m_s is None else np.asarray(v0_m_s, dtype=float)
    if not forces and x0.size == 0 and v0.size == 0:
        raise ValueError("nothing excites the model: give --force, --force-table, --x0-m or --v0-m-s")
    return Simulation(**_vibid.simulate(model._m, forces, dt_s, t_end_s, method, x0, v0))


# --- recordings ---------------------------------------------------------------------------------

_QUANTITY = {"n": ("force", "N"), "m_s2": ("acceleration", "m/s^2"), "m_s": ("velocity", "m/s"),
             "m": ("displacement", "m"), "s": ("time", "s"), "q31": ("force", "Q31"),
             "counts": ("counts", "-")}


_SENSOR_OF_QUANTITY = {"acceleration": "acc", "velocity": "vel", "displacement": "disp"}


def _quantity(name: str):
    for suffix in sorted(_QUANTITY, key=len, reverse=True):
        if name.endswith("_" + suffix):
            return _QUANTITY[suffix]
    return ("unknown", "")


@dataclasses.dataclass(repr=False)
class Recording:
    """A uniformly sampled recording: ``data`` shaped (channels, samples), float64, SI units
    named by the column names' suffixes (``force1_n`` N, ``acc1_m_s2`` m/s^2, ``x2_m`` m)."""
    names: list
    data: np.ndarray
    fs_hz: float
    t0_s: float = 0.0
    sample_index: Optional[np.ndarray] = None  #: the board's tick of each record (acquisitions)
    #: When the board sampled each channel after the clock's edge, {column: us} (acquisitions;
    #: the recording's JSON sidecar holds it)
    sample_instants_us: Optional[dict] = None
    t_s: Optional[np.ndarray] = None  #: the recording's own time column, when it has one

    def index(self, name: str) -> int:
        """The row of a column; ValueError naming the columns there are otherwise."""
        try:
            return self.names.index(name)
        except ValueError:
            raise ValueError(f"unknown column '{name}'; the recording has: "
                             + ", ".join(self.names)) from None

    def __getitem__(self, name: str) -> np.ndarray:
        """One channel by column name (a view, no copy)."""
        return self.data[self.index(name)]

    @property
    def samples(self) -> int:
        return self.data.shape[1]

    def time_s(self) -> np.ndarray:
        """The time of each sample, s: the recording's own column, else t0_s + i / fs_hz (as
        (t0_s fs_hz + i) / fs_hz when t0_s is a whole number of samples: one rounding, so the CSV
        holds the exact decimal)."""
        if self.t_s is not None:
            return self.t_s
        start = self.t0_s * self.fs_hz
        if start == round(start):
            return (round(start) + np.arange(self.samples)) / self.fs_hz
        return self.t0_s + np.arange(self.samples) / self.fs_hz

    def to_sep005(self) -> list:
        """One SEP005 dict per channel: data, fs, name, quantity, unit_str."""
        out = []
        for i, n in enumerate(self.names):
            quantity, unit = _quantity(n)
            out.append({"data": self.data[i], "fs": self.fs_hz, "name": n,
                        "quantity": quantity, "unit_str": unit})
        return out

    @classmethod
    def from_sep005(cls, channels) -> "Recording":
        """From SEP005 channel dicts (a dict or a list of them) of one sample rate."""
        chans = [channels] if isinstance(channels, dict) else list(channels)
        if not chans:
            raise ValueError("no channels")
        fs = {float(c["fs"]) for c in chans}
        if len(fs) != 1:
            raise ValueError("channels of different sample rates: " + ", ".join(map(str, fs)))
        data = np.vstack([np.asarray(c["data"], dtype=float) for c in chans])
        return cls(names=[c["name"] for c in chans], data=data, fs_hz=fs.pop())

    def write_csv(self, path: str) -> None:
        """Writes the recording as a plain CSV (one header row, t_s first, then rows) that reads
        back bit-identical, with its sampling instants in the JSON sidecar PATH.json when it has
        them: an acquisition's files are the ones ``vibid acquire`` writes."""
        _vibid.write_csv(_output_path("path", path), ["t_s"] + list(self.names),
                         np.vstack([self.time_s()[None, :], self.data]),
                         list((self.sample_instants_us or {}).items()))

    def __repr__(self) -> str:
        return _repr("Recording", names=self.names, samples=self.samples, fs_hz=self.fs_hz)


def read_recording(path: str, fs_hz: Optional[float] = None, time_column: str = "t_s",
                   channels: Optional[Sequence[str]] = None) -> Recording:
    """Reads a recording CSV as vibid writes it (``acquire``, ``simulate``): every column but
    the time column, which gives fs_hz (checked uniform) unless ``fs_hz`` is given."""
    names, data, fs, t0, instants = _vibid.read_recording(
        _input_path("path", path), None if fs_hz is None else _real("fs_hz", fs_hz),
        _text("time_column", time_column), _names("channels", channels))
    keep = [i for i, n in enumerate(names) if n != time_column]
    t = data[names.index(time_column)] if time_column in names and fs_hz is None else None
    return Recording(names=[names[i] for i in keep], data=data[keep], fs_hz=fs, t0_s=t0, t_s=t,
                     sample_instants_us=instants or None)


# --- FRF estimation, modes, identification ------------------------------------------------------

def _estimation_options(force="", responses="", estimator="h1", impact=False, welch=False,
                        window="hann", detrend="none", sensor="", kind="receptance",
                        segment=0, overlap=-1, fs_hz=0.0, keep_bad_hits=False,
                        exp_window=None, record_s=None, pretrigger_s=None):
    o = _vibid._EstimationOptions()
    o.force, o.responses = force, responses
    o.estimator, o.impact, o.welch, o.window, o.detrend = estimator, impact, welch, window, detrend
    o.sensor, o.kind, o.segment, o.overlap = sensor, kind, segment, overlap
    o.fs_hz = 0.0 if fs_hz is None else fs_hz
    o.keep_bad_hits = keep_bad_hits
    if exp_window is not None:
        o.exp_window_end = exp_window
    if record_s is not None:
        o.record_s = record_s
    if pretrigger_s is not None:
        o.pretrigger_s = pretrigger_s
    o.validate()
    return o


@dataclasses.dataclass
class Hit:
    """One hammer hit of an impact estimation and its verdict (``used``, or why not)."""
    t_s: float
    peak_n: float
    pulse_width_s: float
    double_hit: bool
    clipped: bool
    truncated: bool
    used: bool
    note: str


@dataclasses.dataclass(repr=False)
class FrfEstimate:
    """``vibid frf-estimate``'s result: the FRF (``frd``, with coherence), which processing ran
    (``impact``: per-hit records; else Welch) and why (``note``), the hits and their verdicts."""
    frd: Frd
    estimator: str
    averages: int
    impact: bool
    hits: list
    note: str
    warnings: list
    compensation: str
    # The used hits' ring-downs (the library's), for the amplitude check of modes of it.
    _ringdowns: object = dataclasses.field(default=None, compare=False, repr=False)

    def __repr__(self) -> str:
        used = sum(h.used for h in self.hits)
        return _repr("FrfEstimate", kind=self.frd.kind, responses=self.frd.outputs,
                     lines=self.frd.freq_hz.size, averages=self.averages,
                     processing="impact" if self.impact else "welch",
                     hits=f"{used}/{len(self.hits)} used")


def _frf_estimate(d) -> FrfEstimate:
    h = np.asarray(d["h"])
    frd = Frd(freq_hz=np.asarray(d["freq_hz"]), h=h.T[:, None, :], kind=d["kind"],
              outputs=list(d["responses"]), inputs=[d["force"]],
              coherence=np.asarray(d["coherence"]).T[:, None, :], _frf=d["_frf"])
    return FrfEstimate(frd=frd, estimator=d["estimator"], averages=d["averages"],
                       impact=d["impact"], hits=[Hit(**h) for h in d["hits"]], note=d["note"],
                       warnings=list(d["warnings"]), compensation=d["compensation"],
                       _ringdowns=d["_ringdowns"])


def frf_estimate(recording, force: str = "", responses="", **options) -> FrfEstimate:
    """FRFs of responses to a force (``vibid frf-estimate``, same options and defaults).

    ``recording`` is a CSV path (``force``/``responses`` are column specs NAME[:UNIT|*FACTOR],
    responses comma separated or a list) or a Recording (column names). Per-hit impact records
    when the force is a train of short pulses (or ``impact=True``), Welch averaging otherwise (or
    ``welch=True``). Options: estimator (h1, h2, hv), window, detrend, sensor (acc, vel, disp,
    for all or one per response as "acc,acc,disp"; default: each response as its unit says, so
    accelerometers and encoders share a test),
    kind (receptance m/N, mobility, accelerance), segment, overlap (samples), fs_hz,
    keep_bad_hits, exp_window, record_s (s), pretrigger_s (s)."""
    names = _names("responses", responses)
    o = _estimation_options(force=_text("force", force), responses=",".join(names), **options)
    if isinstance(recording, Recording):
        force_signal = recording[force]
        idx = [recording.index(n) for n in names]
        # Consecutive rows are a view; any other choice of rows is gathered once.
        if idx and idx == list(range(idx[0], idx[0] + len(idx))):
            x = recording.data[idx[0]:idx[0] + len(idx)]
        else:
            x = recording.data[idx]
        # The board's sampling instants, as the file's sidecar gives them to the CLI.
        instants = recording.sample_instants_us or {}
        instants_s = []
        if instants:
            for n in [force] + names:
                if n not in instants:
                    raise ValueError(f"the recording's sample_instants_us does not name column "
                                     f"'{n}'")
                instants_s.append(instants[n] * 1e-6)
        return _frf_estimate(_vibid.estimate_arrays(force_signal, x, recording.fs_hz, force,
                                                    names, o, instants_s))
    return _frf_estimate(_vibid.estimate_file(_input_path("recording", recording), o))


def frf_estimate_arrays(force, responses, fs_hz: float, force_name: str = "force",
                        response_names: Optional[Sequence[str]] = None,
                        sensor: Optional[str] = None, **options) -> FrfEstimate:
    """frf_estimate on signals in memory, SI units: ``force`` shaped (samples,), ``responses``
    (responses, samples). float64 C-ordered arrays are read in place, without a copy.

    What the responses measure is ``sensor`` (acc, vel or disp), or, when it is not given, read
    from the response names' unit suffixes (``acc1_m_s2`` acc, ``v1_m_s`` vel, ``x1_m`` disp);
    responses of unnamed quantity without ``sensor`` are refused (ValueError), never taken for
    accelerations. ``kind`` (default receptance) is the FRF produced from them."""
    if np.ndim(responses) == 1:
        responses = np.asarray(responses)[None, :]
    force = _signal("force", force, 1)
    responses = _signal("responses", responses, 2)
    names = _names("response_names", response_names) if response_names is not None else [
        f"response{i + 1}" for i in range(responses.shape[0])]
    if sensor is None:
        # Read from the names' unit suffixes, as the board names its columns.
        kinds = {n: _SENSOR_OF_QUANTITY.get(_quantity(n)[0]) for n in names}
        unnamed = [n for n, k in kinds.items() if k is None]
        if unnamed:
            raise ValueError(f"frf_estimate_arrays: what do the responses measure? "
                             f"{', '.join(unnamed)} names no unit: give sensor='acc', 'vel' or "
                             "'disp', or name the responses with their unit (acc1_m_s2, v1_m_s, "
                             "x1_m)")
        found = set(kinds.values())
        sensor = found.pop() if len(found) == 1 else ",".join(kinds[n] for n in names)
    o = _estimation_options(sensor=_text("sensor", sensor), **options)
    return _frf_estimate(_vibid.estimate_arrays(force, responses, _real("fs_hz", fs_hz),
                                                _text("force_name", force_name), names, o, []))


def default_segment(samples: int) -> int:
    """The Welch segment used when none is given (a power of two, at most 4096, a quarter)."""
    return _vibid.default_segment(samples)


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


@dataclasses.dataclass(repr=False)
class Identification:
    """``vibid identify``'s result: the updated model, the validation table (``validation``: the
    CLI's text; ``report``: report.json's data with every interval)."""
    updated: Model
    report: dict
    validation: str

    def __repr__(self) -> str:
        return _repr("Identification", masses_kg=np.diag(self.updated.m_kg),
                     springs=self.report.get("updated_model", {}).get("springs"))


def identify(nominal: Model, mass_tests: dict, modal_tests: Sequence[str],
             mass_springs: Optional[dict] = None, force: str = "force1_n",
             mass_response: str = "", modal_responses: str = "", exp_window: float = 0.0,
             record_s: float = 0.0, welch: bool = False, keep_bad_hits: bool = False,
             method: str = "lscf", orders: str = "") -> Identification:
    """Mass tests and modal tests to an updated model (``vibid identify``): ``mass_tests`` maps
    a mass position (from 1) to its recording, ``mass_springs`` a position to its spring in N/m
    or "fit"."""
    nominal = _model("nominal", nominal)
    r = _vibid._IdentifyRequest()
    for pos, path in mass_tests.items():
        r.add_mass_test(f"{pos}={_input_path(f'mass_tests[{pos}]', path)}")
    r.mass_springs = [f"{p}={k}" for p, k in (mass_springs or {}).items()]
    r.modal_tests = [_input_path("modal_tests", p) for p in
                     ([modal_tests] if isinstance(modal_tests, (str, os.PathLike)) else modal_tests)]
    r.mass_response, r.modal_responses = mass_response, modal_responses
    e = r.estimation
    e.force, e.welch, e.keep_bad_hits = force, welch, keep_bad_hits
    e.exp_window_end, e.record_s = exp_window, record_s
    r.estimation = e
    m = r.modes
    m.method, m.orders = method, orders
    r.modes = m
    chain, report, table = _vibid.identify(nominal._m, r)
    return Identification(updated=Model.from_dict(chain), report=report, validation=table)


@dataclasses.dataclass(repr=False)
class Decay:
    """``vibid decay --json``: damped and natural frequency (rad/s) and damping ratio, averaged
    over the records (``records``: each fit), and with loaded records ``k_n_per_m`` and
    ``base_mass_kg``. ``json`` is the CLI's object."""
    omega_d_rad_s: float
    omega_n_rad_s: float
    zeta: float
    records: list
    k_n_per_m: Optional[float]
    base_mass_kg: Optional[float]
    json: dict

    @property
    def cautions(self) -> list:
        """Friction named, the fit's and the log decrement's damping disagreeing (the CLI's
        CAUTION lines, which exit 6 there); empty for a decay that reads as viscous."""
        return self.json["cautions"]

    def __repr__(self) -> str:
        return _repr("Decay", omega_n_rad_s=self.omega_n_rad_s, zeta=self.zeta,
                     records=len(self.records), k_n_per_m=self.k_n_per_m,
                     base_mass_kg=self.base_mass_kg)


def decay(recordings, position: str, scale: float = 1.0, fs_hz: Optional[float] = None,
          cycles: int = 3, end_fraction: float = 0.1, loaded: Sequence[str] = (),
          added_kg: float = 0.0) -> Decay:
    """Free decay after a pull and release (``vibid decay``, same defaults): finds the release
    and fits x0 + A exp(-sigma t) cos(omega_d t + phi) over the first ``cycles``; ``position`` is
    the column spec NAME[:UNIT|*FACTOR]. With ``loaded`` records (``added_kg`` more on the same
    spring) also the spring (N/m) and the base mass (kg)."""
    r = _vibid._DecayRequest()
    r.recordings = [_input_path("recordings", p) for p in (
        [recordings] if isinstance(recordings, (str, os.PathLike)) else recordings)]
    r.loaded = [_input_path("loaded", p) for p in (
        [loaded] if isinstance(loaded, (str, os.PathLike)) else loaded)]
    r.position, r.scale, r.fs_hz, r.added_kg = position, scale, fs_hz or 0.0, added_kg
    r.cycles, r.end_fraction = cycles, end_fraction
    j = _vibid.decay(r)
    return Decay(omega_d_rad_s=j["omega_d_rad_s"], omega_n_rad_s=j["omega_n_rad_s"], zeta=j["zeta"],
                 records=j["records"], k_n_per_m=j.get("k_n_per_m"),
                 base_mass_kg=j.get("base_mass_kg"), json=j)


# --- system identification ----------------------------------------------------------------------

@dataclasses.dataclass(repr=False)
class SysidModel:
    """An identified model as ``vibid arx|pem|tfest --json`` prints it (``json``: polynomials
    A, B, C, D, F in powers of q^-1 with dt_s, or num/den in s; fits in %, standard deviations,
    residual tests) and the CLI's text (``text``). ``save`` writes the model file ``compare``
    reads."""
    json: dict
    text: str

    @property
    def fit_percent(self) -> float:
        return self.json["fit_percent"]

    @property
    def cautions(self) -> list:
        """The residual tests the model fails, in words (the CLI's CAUTION lines); empty when
        its own tests pass."""
        return self.json.get("cautions", [])

    def save(self, path: str) -> None:
        import json
        with open(path, "w") as f:
            f.write(json.dumps(self.json, indent=2) + "\n")

    def __repr__(self) -> str:
        keys = ("A", "B", "F") if "A" in self.json else ("num", "den")
        return _repr("SysidModel", fit_percent=self.fit_percent,
                     **{k: np.asarray(self.json[k]) for k in keys if k in self.json})


def _poly(recording, input, output, fs_hz, detrend, decimate, estimate_range="",
          validate_range="", d2c=False):
    r = _vibid._SysidRecord()
    r.path, r.input, r.output = str(recording), input, output
    r.fs_hz, r.detrend, r.decimate = fs_hz, detrend, decimate
    p = _vibid._PolyRequest()
    p.record, p.estimate_range, p.validate_range, p.d2c = r, estimate_range, validate_range, d2c
    return p


def arx(recording, input: str, output: str, na: int = -1, nb: int = -1, nk: int = 1,
        select: str = "", max_order: int = 10, fs_hz: Optional[float] = None,
        detrend: str = "none", decimate: int = 1, estimate_range: str = "",
        validate_range: str = "", d2c: bool = False) -> SysidModel:
    """ARX A(q)y = B(q)u + e by least squares (``vibid arx``, same options and defaults):
    columns NAME[:UNIT|*FACTOR], ranges "FIRST:LAST" in samples, ``select`` aic|fpe chooses
    na = nb over 1..max_order."""
    j, text = _vibid.arx(_poly(recording, input, output, fs_hz, detrend, decimate,
                               estimate_range, validate_range, d2c), na, nb, nk, select, max_order)
    return SysidModel(json=j, text=text)


def pem(recording, input: str, output: str, structure: str, orders: str,
        max_iterations: int = 200, fs_hz: Optional[float] = None, detrend: str = "none",
        decimate: int = 1, estimate_range: str = "", validate_range: str = "",
        d2c: bool = False) -> SysidModel:
    """Prediction-error model (``vibid pem``): structure arx, armax, oe or bj; orders as NAME=N
    pairs ("nb=5,nf=4,nk=0") or MATLAB's vector ("2,2,1")."""
    j, text = _vibid.pem(_poly(recording, input, output, fs_hz, detrend, decimate,
                               estimate_range, validate_range, d2c), structure, orders,
                         max_iterations)
    return SysidModel(json=j, text=text)


def tfest(recording, input: str, output: str, np: int = 2, nz: int = 0, ic: str = "zero",
          estimate_range: str = "", validate_range: str = "", max_iterations: int = 200,
          fs_hz: Optional[float] = None, detrend: str = "none", decimate: int = 1) -> SysidModel:
    """Continuous-time transfer function num(s)/den(s) (``vibid tfest``): np poles, nz zeros,
    initial conditions zero or estimate."""
    p = _poly(recording, input, output, fs_hz, detrend, decimate)
    j, text = _vibid.tfest(p.record, np, nz, ic, estimate_range, validate_range, max_iterations)
    return SysidModel(json=j, text=text)


@dataclasses.dataclass(repr=False)
class Comparison:
    """``vibid compare``: the fit (%) of the model's simulated (or predicted) output to the
    record's, the signals (``t_s``, ``y``, ``y_model``, as --write-sim writes them), and the JSON."""
    fit_percent: float
    t_s: np.ndarray
    y: np.ndarray
    y_model: np.ndarray
    json: dict
    text: str

    def __repr__(self) -> str:
        return _repr("Comparison", fit_percent=self.fit_percent, samples=self.t_s.size)


def compare(recording, input: str, output: str, model, horizon="inf", method: str = "exact",
            substeps: int = 1, ic: str = "zero", range: str = "", input_dof: int = 1,
            output_dof: int = 1, fs_hz: Optional[float] = None, detrend: str = "none",
            decimate: int = 1) -> Comparison:
    """Fit of a model's output to a recording (``vibid compare``): ``model`` a model file (arx,
    pem, tfest, or a rig model between input_dof and output_dof) or a SysidModel; horizon "inf"
    (simulation) or K samples ahead."""
    import os
    import tempfile
    p = _poly(recording, input, output, fs_hz, detrend, decimate)
    if isinstance(model, SysidModel):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "model.json")
            model.save(path)
            return compare(recording, input, output, path, horizon, method, substeps, ic, range,
                           input_dof, output_dof, fs_hz, detrend, decimate)
    j, text, t, y, ym = _vibid.compare(p.record, str(model), str(horizon), method, substeps, ic,
                                       range, input_dof, output_dof)
    return Comparison(fit_percent=j["fit_percent"], t_s=t, y=y, y_model=ym, json=j, text=text)


# --- the disturbance observer -------------------------------------------------------------------

@dataclasses.dataclass(repr=False)
class ObserverDesign:
    """``vibid dob design``'s result: ``json`` is the design file's object (what ``vibid dob
    run --design`` and ``Board.cal_upload`` take); the figures beside it as the CLI prints them."""
    json: dict
    max_pole_radius: float
    valid_band_hz: tuple
    predicted_noise_rms_n: float
    predicted_snr_db: float

    @property
    def fs_hz(self) -> float:
        return self.json["options"]["fs_hz"]

    def save(self, path: str) -> None:
        """Writes the design file (JSON)."""
        import json
        with open(path, "w") as f:
            f.write(json.dumps(self.json, indent=2) + "\n")

    def __repr__(self) -> str:
        return _repr("ObserverDesign", fs_hz=self.fs_hz, max_pole_radius=self.max_pole_radius,
                     valid_band_hz=self.valid_band_hz,
                     predicted_noise_rms_n=self.predicted_noise_rms_n)


_DESIGN = _vibid._ObserverDesignRequest()  # the library's defaults, those of `vibid dob design`


def dob_design(model: Model, order: int = _DESIGN.order,
               relative_degree: int = _DESIGN.relative_degree, tau_s: float = _DESIGN.tau_s,
               fs_hz: float = _DESIGN.fs_hz, input_dof: int = _DESIGN.input_dof,
               output_dof: int = _DESIGN.output_dof, sensor: str = _DESIGN.sensor,
               form: str = _DESIGN.form, discretize: str = _DESIGN.discretize,
               prototype: str = _DESIGN.prototype, leak_hz: float = _DESIGN.leak_hz,
               force_fs_n: Optional[float] = None, sensor_fs: Optional[float] = None,
               output_fs_n: float = _DESIGN.output_fs_n, sensors=None) -> ObserverDesign:
    """Designs the observer for a model and quantizes it for the board (``vibid dob design``,
    same defaults): Q of order N and relative degree r with cut-off 1/tau_s rad/s, at fs_hz; the
    force acts on mass input_dof, the sensor on output_dof (from 1); full scales in N (force,
    output) and the sensor's unit. ``sensors`` (a sensors file's path or its JSON object, as
    ``cal_upload`` takes) gives the force and sensor full scales, as the board will scale those
    channels (a value given that differs is refused); without it force_fs_n defaults to the
    CLI's (100 N) and sensor_fs to the sensor kind's (0.05 m, 1 m/s or 50 m/s^2)."""
    import json
    model = _model("model", model)
    r = _vibid._ObserverDesignRequest()
    r.order, r.relative_degree = _integer("order", order), _integer("relative_degree",
                                                                    relative_degree)
    r.tau_s, r.fs_hz = _real("tau_s", tau_s), _real("fs_hz", fs_hz)
    r.input_dof, r.output_dof = _integer("input_dof", input_dof), _integer("output_dof",
                                                                           output_dof)
    r.sensor, r.form = _text("sensor", sensor), _text("form", form)
    r.discretize, r.prototype = _text("discretize", discretize), _text("prototype", prototype)
    r.leak_hz = _real("leak_hz", leak_hz)
    if force_fs_n is not None:
        r.force_fs_n = _real("force_fs_n", force_fs_n)
    if sensor_fs is not None:
        r.sensor_fs = _real("sensor_fs", sensor_fs)
    r.output_fs_n = _real("output_fs_n", output_fs_n)
    if sensors is not None:
        source = "sensors"
        if not isinstance(sensors, dict):
            source = _input_path("sensors", sensors)
            with open(source) as f:
                sensors = json.load(f)
        _vibid.take_sensor_full_scales(r, sensors, source, force_fs_n is not None,
                                       sensor_fs is not None)
    j, radius, lo, hi, noise, snr = _vibid.dob_design(model._m, r)
    return ObserverDesign(json=j, max_pole_radius=radius, valid_band_hz=(lo, hi),
                          predicted_noise_rms_n=noise, predicted_snr_db=snr)


@dataclasses.dataclass(repr=False)
class ObserverRun:
    """The observer's estimate d_hat in N, and (fixed point) the board's integer output."""
    d_hat_n: np.ndarray
    d_hat_q31: Optional[np.ndarray]
    saturations: int

    def __repr__(self) -> str:
        return _repr("ObserverRun", samples=self.d_hat_n.size, saturations=self.saturations)


def dob_run(design, responses, force, fixed: bool = True) -> ObserverRun:
    """Replays the observer on signals in SI units (``vibid dob run``): ``responses`` one array
    per sensor input of the design (or one array), ``force`` the measured force (N). Fixed point
    by default: the board's own kernel, so ``d_hat_q31`` equals a board's logged ``d_hat_q31``
    bit for bit; ``fixed=False`` runs the unquantized design in double precision."""
    j = design.json if isinstance(design, ObserverDesign) else design
    rs = [responses] if isinstance(responses, np.ndarray) and responses.ndim == 1 else list(responses)
    inputs = [_signal("responses", x, 1) for x in rs] + [_signal("force", force, 1)]
    if fixed:
        d, q, sat = _vibid.dob_run_fixed(j, inputs)
        return ObserverRun(d_hat_n=d, d_hat_q31=q, saturations=sat)
    return ObserverRun(d_hat_n=_vibid.dob_run_float(j, inputs), d_hat_q31=None, saturations=0)


def lowpass(x, cutoff_hz: float, fs_hz: float, order: int = 4) -> np.ndarray:
    """Zero-phase Butterworth low-pass (``vibid dob run --lowpass-hz``)."""
    return _vibid.lowpass(_signal("x", x, 1), cutoff_hz, fs_hz, order)


@dataclasses.dataclass
class Agreement:
    """``vibid dob compare``: NRMSE fit (%), correlation, lag of the estimate (s), rms error (N)."""
    fit_percent: float
    correlation: float
    delay_s: float
    rmse_n: float


def dob_compare(estimate, measured, fs_hz: float, max_delay_s: float = 0.0) -> Agreement:
    """Agreement of an estimated disturbance with a measured force (``vibid dob compare``)."""
    return Agreement(**_vibid.dob_compare(_signal("estimate", estimate, 1),
                                          _signal("measured", measured, 1), fs_hz, max_delay_s))


# --- the report ---------------------------------------------------------------------------------

def report(output: str, identify: Optional[str] = None, truth: Optional[str] = None,
           dob: Optional[str] = None, measured: str = "", estimates: Sequence[str] = (),
           skip_s: float = 0.0, notes: Sequence[str] = (), title: str = "vibid rig report") -> None:
    """Writes the HTML report (``vibid report``, same options): from the directory
    ``vibid identify --report`` (or ``Identification``'s run) wrote, optionally against the rig's
    true model file, and from an observer recording (``dob``, its ``measured`` force column and
    the ``estimates`` COLUMN[=LABEL], ``skip_s`` seconds left out at each end)."""
    r = _vibid._ReportRequest()
    r.title, r.identify_dir, r.truth = title, str(identify or ""), str(truth or "")
    r.dob_recording, r.measured, r.estimates = str(dob or ""), measured, list(estimates)
    r.skip_s, r.notes = skip_s, list(notes)
    _vibid.report(r, str(output))


# --- the board ----------------------------------------------------------------------------------

def list_devices() -> list:
    """(spec, description) of every board and emulator found (``vibid devices``)."""
    return _vibid.list_devices()


def _settings(seconds, rate_hz, log_rate_hz, decimation, channels, trigger, trigger_timeout_s,
              pretrigger_s, no_dob, allow_drops, scenario, scenario_params):
    """acquire's and stream's arguments, each of its type (TypeError naming it otherwise), in the
    library's settings; their values are checked there, as the CLI's are (ValueError with the
    CLI's message: a length that is not > 0, a rate the board cannot sample...)."""
    s = _vibid._AcquireSettings()
    s.seconds = _real("seconds", seconds)
    s.rate_hz = _real("rate_hz", rate_hz)
    s.log_rate_hz = _real("log_rate_hz", log_rate_hz)
    s.decimation = _integer("decimation", decimation)
    s.channels = _names("channels", channels)
    s.trigger = _text("trigger", trigger)
    s.trigger_timeout_s = _real("trigger_timeout_s", trigger_timeout_s)
    s.pretrigger_s = _real("pretrigger_s", pretrigger_s)
    s.no_dob = _flag("no_dob", no_dob)
    s.allow_drops = _flag("allow_drops", allow_drops)
    return s, _text("scenario", scenario), _reals("scenario_params", scenario_params)


class Board:
    """A board (or vibid-emu) opened by the ``--device`` URL: ``hid``, ``hid:SERIAL``,
    ``usbip://HOST:PORT``, ``serial:PATH``, ``qemu``; "" takes $VIBID_DEVICE, else the only
    board found. Use as a context manager or call close()."""

    def __init__(self, url: str = ""):
        import weakref
        self._b = _vibid._Board(_text("url", url))
        self._watches = weakref.WeakSet()  # live watches: stopped before the board is closed

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        for w in list(self._watches):
            w.close()
        self._b.close()

    def info(self) -> dict:
        """The board's profile, as ``vibid info --json`` prints it."""
        return self._b.info()

    def state(self) -> str:
        """The acquisition state: idle, armed, acquiring, done."""
        return self._b.state()

    def acquire(self, seconds: float, rate_hz: float = 5000.0, log_rate_hz: float = 0.0,
                decimation: int = 0, channels=None, trigger: str = "",
                trigger_timeout_s: float = 0.0, pretrigger_s: float = 0.0, no_dob: bool = False,
                allow_drops: bool = False, scenario: str = "",
                scenario_params: Sequence[float] = ()) -> Recording:
        """Records from the board (``vibid acquire``, same options, defaults and checks) and
        returns the recording in SI units through the board's calibration, with each record's
        tick in ``sample_index``. ``channels``: names (["force1", "acc1"] or "force1,acc1"); all
        when None. d_hat is logged when the board's observer runs, unless ``no_dob``. Every
        argument is checked before the board starts (TypeError for a wrong type, ValueError with
        the CLI's message for a wrong value), and so is the link: an acquisition it cannot carry
        is refused. The memory used is that of the records asked for. However the acquisition
        ends, the records kept are returned: Ctrl-C stops the board and raises
        KeyboardInterrupt; a trigger that does not fire within ``trigger_timeout_s``, a log the
        board overwrote before it could be read, or a board that fails or goes away raises
        DeviceError; each carries the records kept in the exception's ``recording``
        attribute."""
        s, scenario, params = _settings(seconds, rate_hz, log_rate_hz, decimation, channels,
                                        trigger, trigger_timeout_s, pretrigger_s, no_dob,
                                        allow_drops, scenario, scenario_params)
        names, data, fs, index, instants, end = self._b.acquire(s, scenario, params)
        rec = Recording(names=names[1:], data=data[1:], fs_hz=fs,
                        t0_s=float(data[0, 0]) if data.shape[1] else 0.0,
                        sample_index=index, sample_instants_us=instants or None, t_s=data[0])
        if end == "interrupted":
            e = KeyboardInterrupt(f"acquisition stopped by Ctrl-C: kept {rec.samples} records")
            e.recording = rec
            raise e
        if end:
            kind, why = end.split(": ", 1)
            e = DeviceError(why if kind == "incomplete" else
                            f"{why}: acquisition stopped, kept {rec.samples} records" if
                            kind == "trigger-timeout" else
                            f"{why}; kept the {rec.samples} records that had arrived")
            e.recording = rec
            raise e
        return rec

    def stream(self, seconds: float, rate_hz: float = 5000.0, log_rate_hz: float = 0.0,
               decimation: int = 0, channels=None, trigger: str = "",
               trigger_timeout_s: float = 0.0, pretrigger_s: float = 0.0, no_dob: bool = False,
               allow_drops: bool = False, scenario: str = "",
               scenario_params: Sequence[float] = ()) -> Iterator[Recording]:
        """The acquisition of ``acquire`` (same options, checks, preflight and calibration),
        yielding its records in blocks (Recordings, ``sample_index`` the board's ticks) as the
        board's reports arrive; every record exactly once, in order. Leaving the loop early
        (``break``, an exception, Ctrl-C) stops the board; the records after the last block are
        then not yielded. The arguments are checked when it is called, before the first block is
        asked for."""
        s, scenario, params = _settings(seconds, rate_hz, log_rate_hz, decimation, channels,
                                        trigger, trigger_timeout_s, pretrigger_s, no_dob,
                                        allow_drops, scenario, scenario_params)
        if s.trigger_timeout_s > 0.0 and s.trigger:
            raise ValueError("trigger_timeout_s: a stream waits for its trigger until the loop "
                             "is left; leave the loop to give up")
        st = self._b.stream_start(s, scenario, params)
        return self._blocks(st)

    @staticmethod
    def _blocks(st) -> Iterator[Recording]:
        fs = st.fs_hz
        next_index = 0
        finished = False

        def block(names, data, index):
            return Recording(names=names[1:], data=data[1:], fs_hz=fs,
                             t0_s=float(data[0, 0]) if data.shape[1] else 0.0,
                             sample_index=index, t_s=data[0])
        try:
            while True:
                r = st.next(0.1)
                if r[0] == "end":
                    break
                if r[0] == "wait":
                    continue
                _, first, names, data, index = r
                skip = max(0, next_index - first)  # a resumed stream may send a record again
                if skip >= index.size:
                    continue
                next_index = first + index.size
                yield block(names, data[:, skip:], index[skip:])
            names, data, index, _ = st.finish(next_index)
            finished = True
            if index.size:
                yield block(names, data, index)
        finally:
            if not finished:
                st.stop()
                try:
                    st.finish(next_index)
                except DeviceError:
                    pass

    def watch(self, seconds: Optional[float] = None, rate_hz: float = 1000.0, **options):
        """The rig watched on the board (``vibid watch --device``, the same runner, options and
        defaults): the acquisition started, preflighted and run as ``acquire`` runs it
        (``rate_hz``, ``log_rate_hz``, ``decimation``, ``channels`` (default acc1, acc2),
        ``no_dob``, ``scenario``, ``scenario_params``), for ``seconds`` (None: until the loop is
        left), and its records fed to the watch as they arrive. Returns a ``LiveWatch`` that
        yields each ``WatchBlock`` as the records complete it; ``responses``, ``reference`` (a
        recording file), ``journal`` and the analysis options are ``vibid.watch``'s. When the
        board logs its model test (``model_g``, ``model_stale``) every block carries its flag.
        Every option is checked (and the journal created) here, before the board is touched;
        leaving the loop (``break``, Ctrl-C) stops the board and keeps the journal."""
        from ._watch import _board_watch
        return _board_watch(self, seconds, rate_hz, **options)

    def cal_upload(self, model, design, sensors=None, label: str = "") -> dict:
        """Builds the calibration record and stages it on the board (``vibid cal upload``):
        ``model`` a Model or a model file, ``design`` an ObserverDesign (or its JSON),
        ``sensors`` a sensors file's path or its JSON object (None: the scaling the board
        already holds); the label defaults to the model file's name. cal_commit() makes it
        permanent."""
        import json
        if isinstance(model, Model):
            m, default_label = model, "model"
        elif isinstance(model, (str, os.PathLike)):
            m, default_label = load_model(model), _vibid.label_from_model_path(os.fspath(model))
        else:
            raise TypeError(f"model: expected a vibid.Model or a model file's path, got "
                            f"{_kind(model)}")
        if sensors is not None and not isinstance(sensors, dict):
            with open(_input_path("sensors", sensors)) as f:
                sensors = json.load(f)
        if isinstance(design, ObserverDesign):
            j = design.json
        elif isinstance(design, dict):
            j = design
        else:
            raise TypeError(f"design: expected an ObserverDesign (dob_design) or its JSON "
                            f"object, got {_kind(design)}")
        return self._b.cal_upload(m._m, j, sensors, _text("label", label) or default_label)

    def cal_commit(self) -> dict:
        """Writes the staged calibration record to flash (``vibid cal commit``)."""
        return self._b.cal_commit()

    def dob_start(self) -> None:
        """Runs the observer of the active calibration (``vibid dob start``)."""
        self._b.dob(True)

    def dob_stop(self) -> None:
        """Stops the observer (``vibid dob stop``); acquisitions then log no d_hat by default."""
        self._b.dob(False)

    def __repr__(self) -> str:
        return f"Board({self._b.describe()!r})"


# --- the watch ----------------------------------------------------------------------------------

from ._watch import (LiveWatch, OmaModes, Watch, WatchBlock, WatchMode,  # noqa: E402
                     WatchReference, WatchSession, ssi_cov, watch)
