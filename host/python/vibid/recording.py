"""Recordings: uniformly sampled channels in SI units, read from and written to vibid's CSV, and
SEP005 channel dicts."""
from __future__ import annotations

import dataclasses
import json
from typing import Optional, Sequence

import numpy as np

from . import _vibid
from ._checks import _input_path, _names, _output_path, _real, _repr, _text

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
    #: What the recording states of itself, its JSON sidecar as a dict (file-formats.md): rate,
    #: start, board, calibration, the acquisition's options, per channel its unit, sensitivity,
    #: full scale, converter rails and clip count. None for a recording without one.
    facts: Optional[dict] = None

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
        back bit-identical, with its facts (or, without them, its sampling instants) in the JSON
        sidecar PATH.json: an acquisition's files are the ones ``vibid acquire`` writes."""
        _vibid.write_csv(_output_path("path", path), ["t_s"] + list(self.names),
                         np.vstack([self.time_s()[None, :], self.data]),
                         list((self.sample_instants_us or {}).items()),
                         None if self.facts is None else json.dumps(self.facts))

    def __repr__(self) -> str:
        return _repr("Recording", names=self.names, samples=self.samples, fs_hz=self.fs_hz)


def read_recording(path: str, fs_hz: Optional[float] = None, time_column: str = "t_s",
                   channels: Optional[Sequence[str]] = None) -> Recording:
    """Reads a recording CSV as vibid writes it (``acquire``, ``simulate``): every column but
    the time column, which gives fs_hz (checked uniform) unless ``fs_hz`` is given."""
    names, data, fs, t0, instants, facts = _vibid.read_recording(
        _input_path("path", path), None if fs_hz is None else _real("fs_hz", fs_hz),
        _text("time_column", time_column), _names("channels", channels))
    keep = [i for i, n in enumerate(names) if n != time_column]
    t = data[names.index(time_column)] if time_column in names and fs_hz is None else None
    return Recording(names=[names[i] for i in keep], data=data[keep], fs_hz=fs, t0_s=t0, t_s=t,
                     sample_instants_us=instants or None,
                     facts=None if facts is None else json.loads(facts))
