# Types of the extension module vibid._vibid, for editors and type checkers. The public API is
# vibid/__init__.py (annotated in place); these are the conversions it calls.
from typing import Any, List, Optional, Tuple

import numpy as np
import numpy.typing as npt

F64 = npt.NDArray[np.float64]

__version__: str

class DeviceError(RuntimeError): ...
class NumericalError(ArithmeticError): ...
class FlaggedResultError(ValueError): ...

class _Model:
    m_kg: F64
    c_ns_per_m: F64
    k_n_per_m: F64
    dofs: int
    def __init__(self, m_kg: F64, k_n_per_m: F64, c_ns_per_m: Optional[F64] = ...) -> None: ...
    def to_dict(self) -> dict: ...

class _AcquireSettings:
    seconds: float
    rate_hz: float
    log_rate_hz: float
    decimation: int
    channels: List[str]
    trigger: str
    pretrigger_s: float
    trigger_timeout_s: float
    no_dob: bool
    allow_drops: bool

class _Stream:
    fs_hz: float
    def next(self, timeout_s: float) -> tuple: ...
    def stop(self) -> None: ...
    def finish(self, next: int) -> Tuple[List[str], F64, npt.NDArray[np.uint32], bool]: ...

class _Board:
    def __init__(self, url: str) -> None: ...
    def describe(self) -> str: ...
    def info(self) -> dict: ...
    def state(self) -> str: ...
    def acquire(self, settings: _AcquireSettings, scenario: str,
                scenario_params: List[float]) -> tuple: ...
    def stream_start(self, settings: _AcquireSettings, scenario: str,
                     scenario_params: List[float]) -> _Stream: ...
    def cal_upload(self, model: _Model, design: dict, sensors: Optional[dict],
                   label: str) -> dict: ...
    def watch_start(self, settings: _AcquireSettings, scenario: str, scenario_params: List[float],
                    responses: List[str], reference: str, options: _WatchOptions,
                    journal: str) -> _BoardWatch: ...
    def cal_commit(self) -> dict: ...
    def dob(self, run: bool) -> None: ...
    def close(self) -> None: ...

class _EstimationOptions:
    force: str
    responses: str
    estimator: str
    impact: bool
    welch: bool
    window: str
    detrend: str
    sensor: str
    kind: str
    segment: int
    overlap: int
    fs_hz: float
    keep_bad_hits: bool
    exp_window_end: float
    record_s: float
    pretrigger_s: float
    def validate(self) -> None: ...

class _ModeRequest:
    method: str
    orders: str
    driving_point: str
    driving_point_source: str
    fmin_hz: float
    fmax_hz: float

class _IdentifyRequest:
    mass_springs: List[str]
    modal_tests: List[str]
    mass_response: str
    modal_responses: str
    estimation: _EstimationOptions
    modes: _ModeRequest
    def add_mass_test(self, text: str) -> None: ...

class _DecayRequest:
    recordings: List[str]
    loaded: List[str]
    position: str
    scale: float
    fs_hz: float
    added_kg: float
    cycles: int
    end_fraction: float

class _SysidRecord:
    path: str
    input: str
    output: str
    fs_hz: Optional[float]
    detrend: str
    decimate: int

class _PolyRequest:
    record: _SysidRecord
    estimate_range: str
    validate_range: str
    d2c: bool

class _ReportRequest:
    title: str
    identify_dir: str
    truth: str
    dob_recording: str
    measured: str
    estimates: List[str]
    skip_s: float
    notes: List[str]
    accept_flagged: bool

class _ObserverDesignRequest:
    order: int
    relative_degree: int
    tau_s: float
    fs_hz: float
    input_dof: int
    output_dof: int
    sensor: str
    form: str
    discretize: str
    prototype: str
    leak_hz: float
    force_fs_n: float
    sensor_fs: float
    output_fs_n: float

def take_sensor_full_scales(request: _ObserverDesignRequest, sensors: dict, source: str,
                            force_given: bool, sensor_given: bool, input_dof_given: bool,
                            output_dof_given: bool, sensor_kind_given: bool) -> str: ...
def load_model(path: str) -> _Model: ...
def model_from_dict(d: dict, source: str = ...) -> _Model: ...
def model_verdict(d: dict, source: str = ...) -> dict: ...
def require_usable(verdict: dict, accept_flagged: bool, what: str, step: str, option: str) -> None: ...
def format_verdict(verdict: dict) -> str: ...
def modal(model: _Model) -> dict: ...
def frf(model: _Model, input_dof: int, output_dof: int, kind: str,
        omega_rad_s: F64) -> npt.NDArray[np.complex128]: ...
def simulate(model: _Model, forces: List[str], dt_s: float, t_end_s: float, method: str,
             x0_m: F64, v0_m_s: F64) -> dict: ...
def read_recording(path: str, fs_hz: Optional[float], time_column: str,
                   channels: List[str]) -> Tuple[List[str], F64, float, float, dict]: ...
def write_csv(path: str, names: List[str], data: F64,
              sample_instants_us: List[Tuple[str, float]]) -> None: ...
def estimate_file(path: str, options: _EstimationOptions) -> dict: ...
def estimate_arrays(force: F64, responses: F64, fs_hz: float, force_name: str,
                    response_names: List[str], options: _EstimationOptions,
                    instants_s: List[float]) -> dict: ...
def default_segment(samples: int) -> int: ...
def modes(inputs: List[str], options: _EstimationOptions, request: _ModeRequest) -> dict: ...

class _Frf: ...
class _RingDowns: ...

def modes_of(frfs: List[_Frf], sources: List[str], request: _ModeRequest,
             ringdowns: Optional[_RingDowns] = None) -> dict: ...
def frf_from_arrays(freq_hz: F64, h: npt.NDArray[np.complex128], coherence: Optional[F64],
                    kind: str, responses: List[str], force: str) -> _Frf: ...
def identify(nominal: _Model, request: _IdentifyRequest) -> Tuple[dict, dict, str]: ...
def decay(request: _DecayRequest) -> dict: ...
def dob_design(model: _Model, request: _ObserverDesignRequest) -> tuple: ...
def dob_run_fixed(design: dict, inputs: List[F64]) -> Tuple[F64, npt.NDArray[np.int32], int]: ...
def dob_run_float(design: dict, inputs: List[F64]) -> F64: ...
def lowpass(x: F64, cutoff_hz: float, fs_hz: float, order: int) -> F64: ...
def dob_compare(estimate: F64, measured: F64, fs_hz: float, max_delay_s: float) -> dict: ...
def label_from_model_path(path: str) -> str: ...
def list_devices() -> List[Tuple[str, str]]: ...
def arx(poly: _PolyRequest, na: int, nb: int, nk: int, select: str,
        max_order: int) -> Tuple[dict, str]: ...
def pem(poly: _PolyRequest, structure: str, orders: str, max_iterations: int) -> Tuple[dict, str]: ...
def tfest(record: _SysidRecord, np: int, nz: int, ic: str, estimate_range: str,
          validate_range: str, max_iterations: int) -> Tuple[dict, str]: ...
def compare(record: _SysidRecord, model: str, horizon: str, method: str, substeps: int, ic: str,
            range: str, input_dof: int, output_dof: int) -> Tuple[dict, str, F64, F64, F64]: ...
def report(request: _ReportRequest, output: str) -> None: ...

class _WatchOptions:
    fs_hz: float
    channels: int
    reference_s: float
    block_s: float
    window_blocks: int
    sequential_blocks: int
    false_alarm_per_hour: float
    fmax_hz: float
    modes_s: float
    order: int
    def window_false_alarm(self) -> float: ...
    def block_false_alarm(self) -> float: ...

class _WatchSession:
    has_reference: bool
    reference_left_s: float
    def __init__(self, options: _WatchOptions) -> None: ...
    def set_reference(self, reference: F64) -> None: ...
    def feed(self, samples: F64, board: Optional[F64],
             t_first_s: Optional[float]) -> List[Tuple[str, str]]: ...
    def gap(self, missing: int) -> None: ...
    def set_board_threshold(self, h: float) -> None: ...
    def reference(self) -> Optional[dict]: ...
    def header(self) -> Optional[str]: ...

def watch_columns(names: List[str], requested: List[str],
                  source: str) -> Tuple[List[str], Optional[str], Optional[str]]: ...

class _BoardWatch:
    fs_hz: float
    def next(self, timeout_s: float) -> tuple: ...
    def stop(self) -> None: ...

class _SsiCovOptions:
    fs_hz: float
    fmax_hz: float
    fmin_hz: float
    order_max: int

def ssi_cov(responses: F64, options: _SsiCovOptions) -> dict: ...
