"""vibid: identification of mass-spring vibration rigs and the board's disturbance observer.

The functions mirror the ``vibid`` command line (``vibid.modal`` does what ``vibid modal`` does,
with the same defaults) and call the same C++ library. Units are SI and named in every field
(``freq_hz``, ``omega_rad_s``, ``m_kg``...). Arrays are float64; a recording's ``data`` is shaped
(channels, samples); an FRF's ``h`` is shaped (n_out, n_in, n_freq) beside its ``freq_hz``, as
python-control's FRD. Bad input raises ValueError with the CLI's message, an argument of the
wrong type TypeError, a file that is not there FileNotFoundError; board errors raise
vibid.DeviceError. A flagged result or model raises vibid.FlaggedResultError (a ValueError) unless
accepted with ``accept_flagged=True`` (``identify``, ``dob_design``, ``report``,
``Board.cal_upload``).

The package's modules by topic (the names below are the public ones, each importable from
``vibid`` itself): ``model`` (models, modes, FRFs, simulation), ``recording``, ``estimation``
(FRFs of recordings), ``modal_fit`` (modes of a hammer test), ``identification``, ``sysid``,
``observer``, ``reporting``, ``board`` and the watch.
"""
from __future__ import annotations

from ._vibid import DeviceError, FlaggedResultError, NumericalError, __version__
from .board import Board, list_devices
from .estimation import FrfEstimate, Hit, default_segment, frf_estimate, frf_estimate_arrays
from .identification import Decay, Identification, decay, identify
from .modal_fit import Modes, modes
from .model import Frd, Modal, Model, Simulation, frf, load_model, modal, simulate
from .observer import (Agreement, ObserverDesign, ObserverRun, dob_compare, dob_design, dob_run,
                       lowpass)
from .recording import Recording, read_recording
from .reporting import report
from .sysid import Comparison, SysidModel, arx, compare, pem, tfest
from ._watch import (LiveWatch, OmaModes, Watch, WatchBlock, WatchMode, WatchReference,
                     WatchSession, ssi_cov, watch)

__all__ = [
    "DeviceError", "FlaggedResultError", "Model", "load_model", "modal", "Modal", "frf", "Frd", "simulate",
    "Simulation", "Recording", "read_recording", "Board", "list_devices", "frf_estimate",
    "FrfEstimate", "Hit", "modes", "Modes", "identify", "Identification", "default_segment",
    "frf_estimate_arrays", "dob_design", "ObserverDesign", "dob_run", "ObserverRun", "lowpass",
    "dob_compare", "Agreement", "decay", "Decay", "NumericalError", "SysidModel", "arx", "pem",
    "tfest", "compare", "Comparison", "report", "watch", "Watch", "WatchSession", "WatchBlock",
    "WatchMode", "WatchReference", "LiveWatch", "ssi_cov", "OmaModes",
]

