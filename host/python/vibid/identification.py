"""A rig's parameters from its tests: mass and modal tests to an updated model (``vibid
identify``), a spring and mass from free decays (``vibid decay``)."""
from __future__ import annotations

import dataclasses
import os
from typing import Mapping, Optional, Sequence, Union

import numpy as np

from . import _vibid
from ._vibid import FlaggedResultError
from ._checks import _input_path, _kind, _repr
from .model import Model, _model

@dataclasses.dataclass(repr=False)
class Identification:
    """``vibid identify``'s result: the updated model (carrying the verdict, as the model file
    does), the validation table (``validation``: the CLI's text; ``report``: report.json's data
    with every interval) and the verdict: {"level": "ok", "caution" or "flagged", "reasons":
    [{"level", "code", "text"}]}."""
    updated: Model
    report: dict
    validation: str
    verdict: dict

    def __repr__(self) -> str:
        return _repr("Identification", verdict=self.verdict["level"],
                     masses_kg=np.diag(self.updated.m_kg),
                     springs=self.report.get("updated_model", {}).get("springs"))


def identify(nominal: Model, mass_tests: dict, modal_tests: Sequence[str],
             mass_springs: Optional[dict] = None, force: str = "force1_n",
             mass_response: str = "", modal_responses: str = "", exp_window: float = 0.0,
             record_s: float = 0.0, welch: bool = False, keep_bad_hits: bool = False,
             method: str = "lscf", orders: str = "",
             driving_point: Union[str, int] = "",
             accept_flagged: bool = False) -> Identification:
    """Mass tests and modal tests to an updated model (``vibid identify``): ``mass_tests`` maps
    a mass position (from 1) to its recording, ``mass_springs`` a position to its spring in N/m
    or "fit". ``driving_point``: the modal tests' response at the hammer (column name or index
    from 1); left empty it is found from the data, and one the data contradict is refused
    (ValueError naming the one that fits), as the CLI does. The result carries its verdict; a
    flagged one (the updated model fits its own test worse than the nominal) raises
    vibid.FlaggedResultError naming the reasons, as ``vibid identify`` exits 6 and writes no
    model, unless ``accept_flagged=True``: then it is returned, its model carrying the verdict.
    A caution is returned with its reasons."""
    nominal = _model("nominal", nominal)
    if not isinstance(mass_tests, Mapping):
        raise TypeError(f"mass_tests: expected a dict {{position: recording}} (positions from "
                        f"1, e.g. {{1: 'mass1.csv'}}), got {_kind(mass_tests)} {mass_tests!r}")
    if mass_springs is not None and not isinstance(mass_springs, Mapping):
        raise TypeError(f"mass_springs: expected a dict {{position: N/m or 'fit'}}, got "
                        f"{_kind(mass_springs)} {mass_springs!r}")
    if not isinstance(modal_tests, (str, os.PathLike, Sequence)):
        raise TypeError(f"modal_tests: expected a recording's path or a list of them, got "
                        f"{_kind(modal_tests)}")
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
    m.driving_point = "" if driving_point in ("", None) else str(driving_point)
    m.driving_point_source = f"driving_point={driving_point!r}" if m.driving_point else ""
    r.modes = m
    chain, report, table = _vibid.identify(nominal._m, r)
    result = Identification(updated=Model.from_dict(chain), report=report, validation=table,
                            verdict=report["verdict"])
    try:
        _vibid.require_usable(result.verdict, bool(accept_flagged), "the identification",
                              "identify", "accept_flagged=True")
    except FlaggedResultError as e:
        e.identification = result  # what was found, for a look at why
        raise
    return result


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
        CAUTION lines); empty for a decay that reads as viscous."""
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
