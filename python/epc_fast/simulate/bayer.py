"""A Bayer sensor's side of a capture: the RGGB cell's filters over the pixels, and the
camera's development of the read-out mosaic into a luminance image (demosaicking with the
colour-demosaicing package, white balance and the colour correction's luminance row).

colour-demosaicing is imported only by :func:`luminance` (the ``simulate`` extra).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..cfa import (DEFAULT_CFA_TRANSMITTANCE, DEFAULT_CHANNEL_TRANSMITTANCES,
                   DEFAULT_LUMINANCE_WEIGHTS, check_demosaic)
from .._validation import short

__all__ = ["Bayer", "bayer", "PATTERN", "BORDER_PX"]

#: The cell's layout from the image's top-left pixel, in colour-demosaicing's spelling.
PATTERN = "RGGB"
#: Output pixels of scene a Bayer capture images round its chart and crops after
#: demosaicking, so that the chart never sees the demosaicker's image border (Menon's
#: refinement reaches 3 pixels, the others 2); even, so the chart's first pixel is red.
BORDER_PX = 4

_FUNCTIONS = {"bilinear": "demosaicing_CFA_Bayer_bilinear",
              "malvar2004": "demosaicing_CFA_Bayer_Malvar2004",
              "menon2007": "demosaicing_CFA_Bayer_Menon2007"}


@dataclass(frozen=True)
class Bayer:
    """A Bayer sensor and its development.

    demosaic : one of :data:`epc_fast.cfa.DEMOSAICS`.
    channels : (t_R, t_G, t_B), each channel's electrons over those of the monochrome sensor
        that K describes (above 1 where a channel collects more), their cell mean
        (t_R + 2 t_G + t_B) / 4 the cfa_transmittance t.
    weights : (y_R, y_G, y_B), sum 1, the luminance row of the colour correction applied to
        white-balanced RGB.
    """

    demosaic: str
    channels: tuple
    weights: tuple

    @property
    def transmittance(self) -> float:
        t = self.channels
        return (t[0] + 2.0 * t[1] + t[2]) / 4.0

    def mosaic(self, shape_out, binning: int) -> np.ndarray:
        """Each sensor pixel's filter transmittance, shape (rows k, columns k): output pixel
        (i, j) is red for even i and j, blue for odd i and j, green else; with binning k its
        k x k sensor pixels share its filter (a quad Bayer sensor at k = 2)."""
        rows, cols = shape_out
        t_r, t_g, t_b = self.channels
        cell = np.array([[t_r, t_g], [t_g, t_b]])
        out = np.tile(cell, ((rows + 1) // 2, (cols + 1) // 2))[:rows, :cols]
        return np.kron(out, np.ones((binning, binning))) if binning > 1 else out

    @property
    def border_px(self) -> int:
        """Output pixels of scene a capture images round its chart for the development."""
        return BORDER_PX

    def luminance(self, raw_e) -> np.ndarray:
        """e- on the cell's scale: each pixel divided by its filter's transmittance (white
        balance, before demosaicking as raw converters do it, so that a grey scene is grey to
        the demosaicker), then :meth:`developed`, so that a flat patch of S monochrome
        electrons gives t S."""
        raw = np.asarray(raw_e, dtype=float)
        return self.developed(raw / self.mosaic(raw.shape, 1))

    def developed(self, balanced) -> np.ndarray:
        """The white-balanced RGGB mosaic ``balanced`` demosaicked, the luminance row applied
        and the result times t."""
        try:
            import colour_demosaicing
        except ImportError as error:
            raise ImportError("cfa='bayer' demosaicks with the colour-demosaicing package: "
                              "pip install 'epc-fast[simulate]'") from error
        demosaicker = getattr(colour_demosaicing, _FUNCTIONS[self.demosaic])
        rgb = np.asarray(demosaicker(balanced, PATTERN), dtype=float)
        return np.ascontiguousarray(rgb @ (np.asarray(self.weights) * self.transmittance))


def bayer(demosaic="malvar2004", cfa_transmittance=None, channel_transmittances=None,
          luminance_weights=None) -> Bayer:
    """A checked :class:`Bayer`. The channels default to the Nikon D5100's
    (:data:`~epc_fast.cfa.DEFAULT_CHANNEL_TRANSMITTANCES`), scaled by one factor so that their
    cell mean is ``cfa_transmittance`` (default :data:`~epc_fast.cfa.DEFAULT_CFA_TRANSMITTANCE`);
    the weights default to :data:`~epc_fast.cfa.DEFAULT_LUMINANCE_WEIGHTS`."""
    check_demosaic(demosaic)
    channels = _triple("channel_transmittances",
                       DEFAULT_CHANNEL_TRANSMITTANCES if channel_transmittances is None
                       else channel_transmittances)
    if np.any(channels <= 0.0):
        raise ValueError(f"channel_transmittances: three positive transmittances, got "
                         f"{short(channel_transmittances)}")
    weights = _triple("luminance_weights", DEFAULT_LUMINANCE_WEIGHTS
                      if luminance_weights is None else luminance_weights)
    if abs(weights.sum() - 1.0) > 1e-9:
        raise ValueError(f"luminance_weights: three weights summing to 1 (white's luminance), "
                         f"got {short(luminance_weights)}")
    if cfa_transmittance is not None:
        t = np.asarray(cfa_transmittance, dtype=float) if _real(cfa_transmittance) else None
        if t is None or t.size != 1 or not 0.0 < float(t) <= 1.0:
            raise ValueError(f"cfa_transmittance: a transmittance in (0, 1], got "
                             f"{short(cfa_transmittance)}")
        mean = (channels[0] + 2.0 * channels[1] + channels[2]) / 4.0
        channels = channels * (float(t) / mean)
    return Bayer(demosaic, tuple(float(c) for c in channels), tuple(float(w) for w in weights))


def _real(value) -> bool:
    try:
        a = np.asarray(value)
        return a.dtype.kind in "iuf" and bool(np.all(np.isfinite(a)))
    except (TypeError, ValueError):
        return False


def _triple(name, value) -> np.ndarray:
    if not _real(value) or np.shape(value) != (3,):
        raise ValueError(f"{name}: three finite numbers (R, G, B), got {short(value)}")
    return np.asarray(value, dtype=float)
