"""Type stubs for epc_fast's compiled core (cpp/src/module.cpp and the register_*.cpp files it
calls). Use epc_fast.evaluate."""

from typing import Callable, Protocol, Sequence

import numpy as np
import numpy.typing as npt

n_params: int
parameter_names: tuple[str, ...]  # the model parameters, in the core's order (params.PARAMETER_NAMES)
block_size: int
stream_min_bytes: int
streaming_stores: bool
isa: str
module_name: str
MODULES: dict[str, str]
MAX_THREADS: int  # epc_fast._threads.MAX_THREADS

def cpu_levels() -> dict[str, bool]: ...
def openmp_enabled() -> bool: ...
def default_threads() -> int: ...
def started_threads() -> int: ...  # the most threads the calling thread's calls ran on
def checked_default_threads() -> int: ...  # _core.py: default_threads() within MAX_THREADS
def evaluate(
    columns: Sequence[npt.NDArray[np.float64]],
    size_is_pixel_count: bool,
    domains: npt.NDArray[np.float64],
    wavelengths_nm: npt.NDArray[np.float64],
    weights: npt.NDArray[np.float64],
    n: int,
    f50_solver: str,
    f50_rtol: float,
    t_mpe_solver: str,
    t_mpe_rtol: float,
    precision: str,
    threads: int,
    chunk_points: int,
    out: dict[str, np.ndarray] | None = None,
    allocate: Sequence[str] | None = None,
    lens_tables: Sequence[tuple[np.ndarray, np.ndarray, np.ndarray]] | None = None,
    demosaic_table: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    epc_both: bool = False,
    modes: Sequence[tuple[float | None, float | None, float | None, float | None]] | None = None,
) -> dict[str, np.ndarray]:
    """``out``'s arrays and new ones for the outputs named in ``allocate`` (None: the eight
    default ones when ``out`` is None, else none), written; the outputs in neither are not
    computed. The shares (``share_diffraction`` ...) and the single elasticities
    (``"elasticity_"`` and a name of ``parameter_names``) are 1-D of ``n``, as the others are;
    ``elasticities`` (every elasticity, not with single ones) holds ``n_params`` rows of ``n``
    values, flat. ``f50_across_cyc_per_mm`` is the f50 without the motion blur; ``epc_both``
    counts EPC and the status in both directions (neither with shares or elasticities).
    ``modes``: (binning, binning_readout code, frames, alignment_error_um) per readout mode,
    None where the column stays; each point then takes its best mode's outputs, and ``mode``
    (int16, -1 where no mode has a finite EPC) is added."""
def float_arrays(
    names: tuple[str, ...],
    values: tuple[object, ...],
    kept: dict[float, np.ndarray],
    convert: Callable[[str, object], np.ndarray],
) -> tuple[list[np.ndarray], set[tuple[int, ...]]]:
    """epc_fast._validation.float_arrays: the values as float64 arrays (kept floats' arrays and
    float64 ndarrays as they are, the rest through ``convert``) and their shapes but ()."""
def output_cache(limit_bytes: int | None = None) -> dict[str, int]:
    """Sets the output cache's limit (bytes) when given; {"limit_bytes", "retained_bytes"}."""
def best_mode(epcs: Sequence[npt.NDArray[np.float64]], threads: int) -> npt.NDArray[np.int16]:
    """Per point the first mode of the largest finite EPC among the modes' 1-d arrays; -1
    where none is finite (epc_fast.modes)."""
def take_mode(
    mode: npt.NDArray[np.int16], values: Sequence[np.ndarray], threads: int,
) -> np.ndarray:
    """values[mode[i]][i] per point (the first mode's where mode is -1), one 1-d array of one
    dtype per mode (epc_fast.modes)."""
def lux_for_epc(
    columns: Sequence[npt.NDArray[np.float64]],
    size_is_pixel_count: bool,
    domains: npt.NDArray[np.float64],
    wavelengths_nm: npt.NDArray[np.float64],
    weights: npt.NDArray[np.float64],
    n: int,
    target_epc: npt.NDArray[np.float64],
    lux_lo: float,
    lux_hi: float,
    rtol: float,
    f50_rtol: float,
    threads: int,
) -> dict[str, np.ndarray]: ...
def crossover_lux(
    columns_a: Sequence[npt.NDArray[np.float64]],
    columns_b: Sequence[npt.NDArray[np.float64]],
    size_is_pixel_count_a: bool,
    size_is_pixel_count_b: bool,
    domains: npt.NDArray[np.float64],
    wavelengths_nm: npt.NDArray[np.float64],
    weights: npt.NDArray[np.float64],
    n: int,
    lux_lo: float,
    lux_hi: float,
    grid_points: int,
    rtol: float,
    f50_rtol: float,
    threads: int,
) -> dict[str, np.ndarray]: ...
def scan_chunk(
    space: dict, keys: list, reductions: list, f50_solver: str, f50_rtol: float,
    t_mpe_solver: str, t_mpe_rtol: float, precision: str, start: int, stop: int, threads: int,
    epc_both: bool = False, modes: list | None = None,
) -> list[dict[str, np.ndarray]]: ...
def scan_points(
    space: dict, index: npt.NDArray[np.int64],
) -> tuple[list[np.ndarray | None], list[np.ndarray]]: ...
scan_block_points: int

class _Testing(Protocol):
    """The submodule ``testing`` (cpp/src/register_testing.cpp): single formulas and stages of
    the core, elementwise, for the tests and the benchmarks' Numba peer; not part of the
    package's interface."""

    accurate_start_degree: int
    accurate_start_thresholds: np.ndarray  # the thresholds with an accurate start, in row order
    accurate_start_coefficients: np.ndarray  # (thresholds, terms): each threshold's polynomial
    certified_start_error: np.ndarray  # per start row (the thresholds', then the jitter start's)

    def sinc(self, x: npt.ArrayLike) -> np.ndarray: ...
    def mtf_diffraction(self, nu: npt.ArrayLike) -> np.ndarray: ...
    def mtf_binned_pixel(
        self, f_cyc_per_mm: npt.ArrayLike, aperture_mm: npt.ArrayLike, pitch_mm: npt.ArrayLike,
        binning: npt.ArrayLike,
    ) -> np.ndarray: ...
    def mtf_alignment(
        self, f_cyc_per_mm: npt.ArrayLike, alignment_error_mm: npt.ArrayLike,
        frames: npt.ArrayLike,
    ) -> np.ndarray: ...
    def gaussian_blur_mm(
        self, jitter_um: npt.ArrayLike, alignment_error_um: npt.ArrayLike, frames: npt.ArrayLike,
    ) -> np.ndarray: ...
    def signal_electrons(
        self,
        rate: npt.ArrayLike, snr_db: npt.ArrayLike, read: npt.ArrayLike, dark: npt.ArrayLike,
        prnu: npt.ArrayLike,
    ) -> np.ndarray: ...
    def signal_electrons_brent(
        self,
        rate: npt.ArrayLike, snr_db: npt.ArrayLike, read: npt.ArrayLike, dark: npt.ArrayLike,
        prnu: npt.ArrayLike, rtol: npt.ArrayLike,
    ) -> np.ndarray: ...
    def f50_start(
        self,
        lambda_f_mm: npt.ArrayLike, aperture_mm: npt.ArrayLike, blur_mm: npt.ArrayLike,
        jitter_mm: npt.ArrayLike, mtf_threshold: npt.ArrayLike,
    ) -> np.ndarray: ...
    def f50_cubic_start(
        self,
        lambda_f_mm: npt.ArrayLike, aperture_mm: npt.ArrayLike, blur_mm: npt.ArrayLike,
        jitter_mm: npt.ArrayLike, mtf_threshold: npt.ArrayLike,
    ) -> np.ndarray: ...
    def spectrum_start(
        self,
        wavelengths_nm: npt.NDArray[np.float64], weights: npt.NDArray[np.float64],
    ) -> dict[str, np.ndarray]: ...
    def lens_start(self, table: tuple) -> dict[str, np.ndarray | float] | None: ...
    def pixel_start(self, table: tuple) -> dict[str, np.ndarray | float] | None: ...
    def f50_pixel_start(
        self, table: tuple, lambda_f_mm: npt.ArrayLike, pitch_mm: npt.ArrayLike,
        blur_mm: npt.ArrayLike, mtf_threshold: npt.ArrayLike,
    ) -> np.ndarray: ...
    def f50_spectrum_start(
        self,
        wavelengths_nm: npt.NDArray[np.float64], weights: npt.NDArray[np.float64],
        lambda_f_mm: npt.NDArray[np.float64], aperture_mm: npt.NDArray[np.float64],
        blur_mm: npt.NDArray[np.float64], mtf_threshold: npt.NDArray[np.float64],
    ) -> np.ndarray: ...
    def stream_uniforms(
        self, seed: int, stream: int, index: npt.NDArray[np.int64],
    ) -> np.ndarray: ...
    def ndtri(self, p: npt.ArrayLike) -> np.ndarray: ...
    def table_lookup(
        self, table: tuple[np.ndarray, np.ndarray, np.ndarray], f: npt.ArrayLike,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int, int]: ...
    def ndtri_blocks(self, p: npt.ArrayLike) -> np.ndarray: ...
    def elementary_exp(self, x: npt.ArrayLike) -> np.ndarray: ...
    def elementary_exp_normal(self, x: npt.ArrayLike) -> np.ndarray: ...
    def elementary_log(self, x: npt.ArrayLike) -> np.ndarray: ...
    def octave_slots(
        self, values: npt.ArrayLike, first_key: int, bins: int, shift: int,
    ) -> np.ndarray: ...

testing: _Testing
