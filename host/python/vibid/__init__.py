"""vibid: identification of mass-spring vibration rigs and the board's disturbance observer.

The functions mirror the ``vibid`` command line (``vibid.modal`` does what ``vibid modal`` does,
with the same defaults) and call the same C++ library. Units are SI and named in every field
(``freq_hz``, ``omega_rad_s``, ``m_kg``...). Arrays are float64; a recording's ``data`` is shaped
(channels, samples); an FRF's ``h`` is shaped (n_out, n_in, n_freq) beside its ``freq_hz``, as
python-control's FRD. Bad input raises ValueError with the CLI's message; board errors raise
vibid.DeviceError.
"""
from __future__ import annotations

import dataclasses
from typing import Iterable, Optional, Sequence

import numpy as np

from . import _vibid
from ._vibid import DeviceError

__all__ = [
    "DeviceError", "Model", "load_model", "modal", "Modal", "frf", "Frd", "simulate",
    "Simulation", "Recording", "read_recording", "Board", "list_devices",
]


def _repr(name: str, **fields) -> str:
    def short(v):
        if isinstance(v, np.ndarray):
            return f"array{v.shape}" if v.size > 6 else np.array2string(v, precision=6)
        return repr(v)
    return name + "(" + ", ".join(f"{k}={short(v)}" for k, v in fields.items()) + ")"


# --- models -------------------------------------------------------------------------------------

class Model:
    """A lumped-parameter rig M x'' + C x' + K x = F: matrices in kg, N*s/m, N/m."""

    def __init__(self, m_kg, k_n_per_m, c_ns_per_m=None):
        self._m = _vibid._Model(np.asarray(m_kg, dtype=float), np.asarray(k_n_per_m, dtype=float),
                                None if c_ns_per_m is None else np.asarray(c_ns_per_m, dtype=float))

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
        d = {"topology": "chain", "masses": list(map(float, masses_kg)),
             "springs": list(map(float, springs_n_per_m))}
        if dampers_ns_per_m is not None:
            d["dampers"] = list(map(float, dampers_ns_per_m))
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
    return Model._wrap(_vibid.load_model(str(path)))


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
    return Modal(**_vibid.modal(model._m))


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

    @property
    def omega_rad_s(self) -> np.ndarray:
        return 2.0 * np.pi * self.freq_hz

    def __repr__(self) -> str:
        return _repr("Frd", kind=self.kind, shape=self.h.shape, outputs=self.outputs,
                     inputs=self.inputs, freq_hz=self.freq_hz)


def frf(model: Model, freq_hz, input: int = 1, outputs: Optional[Sequence[int]] = None,
        kind: str = "receptance") -> Frd:
    """The model's FRF (``vibid frf``): DOFs counted from 1; outputs default to every DOF."""
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
    sample_instants: str = ""  #: the board's sampling-instant header line (acquisitions)

    def __getitem__(self, name: str) -> np.ndarray:
        """One channel by column name (a view, no copy)."""
        try:
            return self.data[self.names.index(name)]
        except ValueError:
            raise ValueError(f"unknown column '{name}'; the recording has: "
                             + ", ".join(self.names)) from None

    @property
    def samples(self) -> int:
        return self.data.shape[1]

    def time_s(self) -> np.ndarray:
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
        """Writes the recording as a vibid CSV (t_s first) that reads back bit-identical."""
        _vibid.write_csv(str(path), ["t_s"] + list(self.names),
                         np.vstack([self.time_s()[None, :], self.data]))

    def __repr__(self) -> str:
        return _repr("Recording", names=self.names, samples=self.samples, fs_hz=self.fs_hz)


def read_recording(path: str, fs_hz: Optional[float] = None, time_column: str = "t_s",
                   channels: Optional[Sequence[str]] = None) -> Recording:
    """Reads a recording CSV as vibid writes it (``acquire``, ``simulate``): every column but
    the time column, which gives fs_hz (checked uniform) unless ``fs_hz`` is given."""
    names, data, fs, t0 = _vibid.read_recording(str(path), fs_hz, time_column,
                                               list(channels or []))
    keep = [i for i, n in enumerate(names) if n != time_column]
    return Recording(names=[names[i] for i in keep], data=data[keep], fs_hz=fs, t0_s=t0)


# --- the board ----------------------------------------------------------------------------------

def list_devices() -> list:
    """(spec, description) of every board and emulator found (``vibid devices``)."""
    return _vibid.list_devices()


class Board:
    """A board (or vibid-emu) opened by the ``--device`` URL: ``hid``, ``hid:SERIAL``,
    ``usbip://HOST:PORT``, ``serial:PATH``, ``qemu``; "" takes $VIBID_DEVICE, else the only
    board found. Use as a context manager or call close()."""

    def __init__(self, url: str = ""):
        self._b = _vibid._Board(url)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self) -> None:
        self._b.close()

    def info(self) -> dict:
        """The board's profile, as ``vibid info --json`` prints it."""
        return self._b.info()

    def state(self) -> str:
        """The acquisition state: idle, armed, acquiring, done."""
        return self._b.state()

    def acquire(self, seconds: float, rate_hz: float = 5000.0, log_rate_hz: float = 0.0,
                decimation: int = 0, channels: Optional[Sequence[str]] = None,
                trigger: str = "", pretrigger_s: float = 0.0, no_dob: bool = False,
                allow_drops: bool = False, scenario: str = "",
                scenario_params: Sequence[float] = ()) -> Recording:
        """Records from the board (``vibid acquire``, same options and defaults) and returns the
        recording in SI units through the board's calibration, with each record's tick in
        ``sample_index``. An acquisition the link cannot carry is refused before the board starts
        (ValueError with the CLI's message). Ctrl-C stops the board and raises KeyboardInterrupt;
        the records it kept are in the exception's ``recording`` attribute."""
        s = _vibid._AcquireSettings()
        s.seconds, s.rate_hz, s.log_rate_hz, s.decimation = seconds, rate_hz, log_rate_hz, decimation
        s.channels = list(channels or [])
        s.trigger, s.pretrigger_s, s.no_dob, s.allow_drops = trigger, pretrigger_s, no_dob, allow_drops
        names, data, fs, index, instants, interrupted = self._b.acquire(
            s, scenario, [float(p) for p in scenario_params])
        rec = Recording(names=names[1:], data=data[1:], fs_hz=fs,
                        t0_s=float(data[0, 0]) if data.shape[1] else 0.0,
                        sample_index=index, sample_instants=instants)
        if interrupted:
            e = KeyboardInterrupt(f"acquisition stopped by Ctrl-C: kept {rec.samples} records")
            e.recording = rec
            raise e
        return rec

    def cal_commit(self) -> dict:
        """Writes the staged calibration record to flash (``vibid cal commit``)."""
        return self._b.cal_commit()

    def dob_start(self) -> None:
        """Runs the observer of the active calibration (``vibid dob start``)."""
        self._b.dob(True)

    def dob_stop(self) -> None:
        self._b.dob(False)

    def __repr__(self) -> str:
        return f"Board({self._b.describe()!r})"
