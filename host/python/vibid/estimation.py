"""FRF estimation from recordings (``vibid frf-estimate``): impact tests hit by hit, Welch
averaging otherwise."""
from __future__ import annotations

import dataclasses
from typing import Optional, Sequence

import numpy as np

from . import _vibid
from ._checks import _input_path, _names, _real, _repr, _signal, _text
from .model import Frd
from .recording import _SENSOR_OF_QUANTITY, Recording, _quantity

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
        # The converters' rails the recording's facts state: a clip is a sample on one.
        channels = {c["name"]: c for c in (recording.facts or {}).get("channels", [])}
        rails = [tuple(channels[n]["rails"]) for n in [force] + names
                 if "rails" in channels.get(n, {})]
        return _frf_estimate(_vibid.estimate_arrays(
            force_signal, x, recording.fs_hz, force, names, o, instants_s,
            rails if len(rails) == len(names) + 1 else []))
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
