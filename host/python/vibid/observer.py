"""The disturbance observer: its design for the board (``vibid dob design``), its replay on
recorded signals (``vibid dob run``) and its estimate against a measured force (``vibid dob
compare``)."""
from __future__ import annotations

import dataclasses
from typing import Optional

import numpy as np

from . import _vibid
from ._checks import _input_path, _integer, _real, _repr, _signal, _text
from .model import Model, _model

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
               fs_hz: float = _DESIGN.fs_hz, input_dof: Optional[int] = None,
               output_dof: Optional[int] = None, sensor: Optional[str] = None,
               form: str = _DESIGN.form, discretize: str = _DESIGN.discretize,
               prototype: str = _DESIGN.prototype, leak_hz: float = _DESIGN.leak_hz,
               force_fs_n: Optional[float] = None, sensor_fs: Optional[float] = None,
               output_fs_n: float = _DESIGN.output_fs_n, sensors=None,
               accept_flagged: bool = False) -> ObserverDesign:
    """Designs the observer for a model and quantizes it for the board (``vibid dob design``,
    same defaults): Q of order N and relative degree r with cut-off 1/tau_s rad/s, at fs_hz; the
    force acts on mass input_dof, the sensor on output_dof (from 1); full scales in N (force,
    output) and the sensor's unit. ``sensors`` (a sensors file's path or its JSON object, as
    ``cal_upload`` takes) places the observer where ``cal_upload`` with them accepts it, on a
    chain of any length (input_dof and output_dof: load cell force1's mass; sensor: that mass's
    encoder, else its accelerometer; each unless given) and gives the force and sensor full
    scales, as the board will scale those channels (a value given that differs is refused);
    without it input_dof and output_dof default to 2, sensor to disp, force_fs_n to the CLI's
    (100 N) and sensor_fs to the sensor kind's (0.05 m, 1 m/s or 50 m/s^2). A model whose
    verdict is flagged raises vibid.FlaggedResultError unless ``accept_flagged=True``."""
    import json
    model = _model("model", model)
    _vibid.require_usable(model.verdict, bool(accept_flagged), "the model", "dob_design",
                          "accept_flagged=True")
    r = _vibid._ObserverDesignRequest()
    r.order, r.relative_degree = _integer("order", order), _integer("relative_degree",
                                                                    relative_degree)
    r.tau_s, r.fs_hz = _real("tau_s", tau_s), _real("fs_hz", fs_hz)
    if input_dof is not None:
        r.input_dof = _integer("input_dof", input_dof)
    if output_dof is not None:
        r.output_dof = _integer("output_dof", output_dof)
    if sensor is not None:
        r.sensor = _text("sensor", sensor)
    r.form = _text("form", form)
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
                                       sensor_fs is not None, input_dof is not None,
                                       output_dof is not None, sensor is not None)
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
