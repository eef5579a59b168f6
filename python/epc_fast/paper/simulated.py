"""The paper's statements checked on simulated captures, as the paper checked them: each
design's EPC taken from the MTF50 the ISO 12233 e-SFR measures on its simulated slanted-edge
captures (:mod:`epc_fast.simulate`), not from the model's f50; the Rayleigh blur from the
first dark ring of the simulator's PSF, the Fourier transform of its pupil.

Each EPC-based statement is solved on the simulated EPC: a crossover where two designs'
simulated EPCs are equal, a light level where one reaches a pixel count, by bracketing about
the model's value and interpolating linearly in log lux between the bracketing captures.
"""

from __future__ import annotations

import math

import numpy as np

from ..presets import FIGURE_3, HIGH_TIER, LOW_TIER, ZOOM_3X, Design

__all__ = ["simulated_values", "airy_first_dark_ring_lambda_f", "SIMULATED_SEEDS",
           "BRACKET_FACTORS"]

#: Noisy captures a simulated EPC is pooled from.
SIMULATED_SEEDS = 8
#: Multiples of the model's value tried in turn to bracket a simulated root.
BRACKET_FACTORS = (1.0, 0.8, 1.25, 0.6, 1.6, 0.4, 2.5)


def airy_first_dark_ring_lambda_f() -> float:
    """The radius of the first dark ring of the simulator's PSF, in units of lambda F: the
    minimum of the PSF along one axis, the squared magnitude of the Fourier transform of the
    pupil's projection on that axis, sampled 2^20 times over the pupil's period and refined
    by a parabola through the smallest sample and its neighbours."""
    from ..simulate import pupil as lens

    aperture = lens.pupil()
    projection = aperture.sum(axis=0)
    diameter = 2.0 * lens.PUPIL_RADIUS_SAMPLES
    n = 2 ** 20
    psf = np.abs(np.fft.rfft(projection, n)) ** 2
    x = np.arange(psf.size) * diameter / n  # lambda F (see simulate.pupil: 2 R samples = the pupil)
    window = (x > 1.0) & (x < 1.5)
    i = np.flatnonzero(window)[np.argmin(psf[window])]
    a, b, c = psf[i - 1], psf[i], psf[i + 1]
    return float(x[i] + 0.5 * (a - c) / (a - 2 * b + c) * (x[1] - x[0]))


class _SimulatedEPC:
    """EPC of a design at a light level from simulated captures, each point captured once."""

    def __init__(self, seeds: int):
        self.seeds = seeds
        self._cache = {}

    def __call__(self, design: Design, lux: float) -> float:
        from ..simulate.agreement import agreement

        key = (design, float(lux))
        if key not in self._cache:
            # the paper's EPC counts the MTF along the motion alone: no edge across it
            a = agreement(float(lux), seeds=self.seeds, across=False,
                          **design.evaluate_kwargs())
            self._cache[key] = a.epc_sim
        return self._cache[key]

    def root(self, g, model_lux: float) -> float:
        """lux where g(lux) (increasing through 0 near ``model_lux``) is 0; NaN unbracketed."""
        if not math.isfinite(model_lux):
            return math.nan
        tried = []
        for factor in BRACKET_FACTORS:
            lux = model_lux * factor
            value = g(lux)
            if math.isfinite(value):
                tried.append((lux, value))
            tried.sort()
            for (l0, v0), (l1, v1) in zip(tried, tried[1:]):
                if v0 < 0 <= v1:
                    w = v0 / (v0 - v1)
                    return float(math.exp(math.log(l0) + w * (math.log(l1) - math.log(l0))))
        return math.nan


def simulated_values(statements, *, seeds: int = SIMULATED_SEEDS) -> dict:
    """{statement id: value from simulated captures} for the statements a capture can check
    (NaN for the fields of view, which are geometry, and where no bracket is found).

    Parameters
    ----------
    statements : the Statements of :func:`epc_fast.paper.statements` (their preset values
        give where to look).
    seeds : noisy captures per simulated EPC.
    """
    epc = _SimulatedEPC(seeds)
    model = {s.id: s.preset_value for s in statements}
    high = dict(zip(("2.8", "2.2", "1.75", "1.4"), HIGH_TIER))
    low = dict(zip(("2.8", "2.2", "1.75", "1.4"), LOW_TIER))
    ring = airy_first_dark_ring_lambda_f() * 550e-3
    out = {"rayleigh_f2.8": ring * HIGH_TIER[0].f_number,
           "rayleigh_f4.9": ring * ZOOM_3X.f_number}

    def crossover(a, b, sid):
        return epc.root(lambda lux: math.log(epc(a, lux) / epc(b, lux)), model[sid])

    def reaches(d, target, sid):
        return epc.root(lambda lux: math.log(epc(d, lux) / target), model[sid])

    for small, big in (("1.4", "1.75"), ("1.4", "2.2"), ("1.4", "2.8")):
        sid = f"crossover_{small}_{big}"
        # The small pixel loses below the crossover: its log ratio rises through 0 there.
        out[sid] = crossover(high[small], high[big], sid)
        sid = f"crossover_1/8_{small}_{big}"
        out[sid] = crossover(low[small], low[big], sid)
    out["fraction_1.4_100klux"] = epc(high["1.4"], 1e5) / high["1.4"].pixel_count
    out["fraction_2.8_100klux"] = epc(high["2.8"], 1e5) / high["2.8"].pixel_count
    out["vga_1.4"] = reaches(high["1.4"], 640 * 480, "vga_1.4")
    for pitch in ("2.2", "1.75", "1.4"):
        out[f"2mp_{pitch}"] = reaches(high[pitch], 2e6, f"2mp_{pitch}")
    out["2mp_1.75_is"] = reaches(FIGURE_3[1], 2e6, "2mp_1.75_is")
    plain = epc.root(lambda lux: math.log(epc(high["1.75"], lux) / 1e6),
                     _lux_for_model(high["1.75"], 1e6))
    stabilised = epc.root(lambda lux: math.log(epc(high["1.75"].stabilized(), lux) / 1e6),
                          _lux_for_model(high["1.75"].stabilized(), 1e6))
    out["is_4x_light"] = plain / stabilised
    return {s.id: float(out.get(s.id, math.nan)) for s in statements}


def _lux_for_model(design: Design, target: float) -> float:
    from ..inverse import InverseStatus, lux_for_epc

    r = lux_for_epc(design.evaluate_kwargs(), target)
    return float(r.illuminance_lux) if r.status == InverseStatus.OK else math.nan
