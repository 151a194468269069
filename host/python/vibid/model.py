"""Rig models (M x'' + C x' + K x = F) and what follows from one alone: modes, FRFs, time
simulation (``vibid modal``, ``vibid frf``, ``vibid simulate``)."""
from __future__ import annotations

import dataclasses
import os
from typing import Iterable, Optional, Sequence

import numpy as np

from . import _vibid
from ._checks import _counted, _input_path, _kind, _repr

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
        self._verdict = _NO_VERDICT

    @classmethod
    def _wrap(cls, m, verdict: Optional[dict] = None) -> "Model":
        self = cls.__new__(cls)
        self._m = m
        self._verdict = verdict or _NO_VERDICT
        return self

    @classmethod
    def from_dict(cls, d: dict, source: str = "model") -> "Model":
        """From a model file's JSON object (chain, cart or M/K/C matrices), with its verdict; a
        field that is not a finite number is named (ValueError), as in a model file, with
        ``source`` before it."""
        return cls._wrap(_vibid.model_from_dict(d, source), _vibid.model_verdict(d, source))

    @property
    def verdict(self) -> dict:
        """The verdict the model's file carries (``vibid identify`` writes it): {"level": "ok",
        "caution" or "flagged", "reasons": [{"level", "code", "text"}], "stated": bool}; a model
        made in Python or read from a file without one is ok with "stated" False. Board.cal_upload
        and dob_design refuse a flagged one unless given accept_flagged=True."""
        return dict(self._verdict)

    @classmethod
    def chain(cls, masses_kg, springs_n_per_m, dampers_ns_per_m=None) -> "Model":
        """Series chain ground -k1- m1 -k2- m2 ..., dashpots in parallel with the springs. Every
        message counts masses, springs and dampers from 1, as the model file's do."""
        d = {"topology": "chain", "masses": _counted("masses_kg", masses_kg, "mass"),
             "springs": _counted("springs_n_per_m", springs_n_per_m, "spring")}
        if dampers_ns_per_m is not None:
            d["dampers"] = _counted("dampers_ns_per_m", dampers_ns_per_m, "damper")
        return cls.from_dict(d, "Model.chain")

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
    """Reads a model file (JSON), as every ``vibid`` command taking MODEL.json does; the model
    keeps the file's verdict (``Model.verdict``)."""
    import json
    p = _input_path("path", path)
    m = _vibid.load_model(p)
    with open(p) as f:
        return Model._wrap(m, _vibid.model_verdict(json.load(f), p))


# A model no identification judged (made here, or a file without "verdict"): read as ok.
_NO_VERDICT = {"level": "ok", "reasons": [], "stated": False}


def _model(name: str, m) -> "Model":
    if isinstance(m, Model):
        return m
    hint = (" (a model file: vibid.load_model(path))" if isinstance(m, (str, os.PathLike))
            else "")
    raise TypeError(f"{name}: expected a vibid.Model, got {_kind(m)}{hint}")


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
