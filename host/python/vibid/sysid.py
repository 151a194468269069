"""Input-output system identification (``vibid arx``, ``pem``, ``tfest``) and the fit of a model
to a recording (``vibid compare``)."""
from __future__ import annotations

import dataclasses
from typing import Optional

import numpy as np

from . import _vibid
from ._checks import _repr

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
