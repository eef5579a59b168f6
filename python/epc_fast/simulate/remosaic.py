"""A quad Bayer sensor read full size: its mosaic (2 x 2 pixels of one colour in the Bayer
arrangement of those blocks) remosaicked to the RGGB Bayer pattern of the same pitch, then
developed as a Bayer capture (:mod:`~epc_fast.simulate.bayer`).

The remosaic is Hamilton and Adams' adaptive colour plane interpolation (J. F. Hamilton Jr.
and J. E. Adams Jr., "Adaptive color plan interpolation in single sensor color electronic
camera", US patent 5,629,734, 1997) adapted to the quad pattern, the non-learned form of the
task the MIPI 2022 challenge set (Q. Yang et al., "MIPI 2022 Challenge on Quad-Bayer
Re-mosaic: Dataset and Report", ECCV Workshops 2022, arXiv:2209.07060: "the interpolation of
Quad CFA to Bayer at full resolution"). On the white-balanced mosaic X:

1. Green everywhere. A green pixel keeps its value. A red or blue pixel C sits at the edge of
   its 2 x 2 block: along a row its nearest green pixel is the next one outside the block
   (distance 1) and the other the first past its block partner (distance 2), so the linear
   estimate is G_H = (2 G_near + G_far) / 3, and G_V likewise along the column. Hamilton and
   Adams' classifier picks the direction: Delta_H = |G_near - G_far| + |2 C_0 - C_-4 - C_+4|
   (the green's first difference across the pixel and the pixel's own colour's second
   difference at the pattern's period, 4 pixels), Delta_V likewise; G = G_H where Delta_H <
   Delta_V, G_V where Delta_V < Delta_H, their mean where equal.
2. Red and blue by colour differences (Hamilton and Adams' second step): D_C = X - G at the
   pixels of colour C, spread to every pixel as their mean weighted by the bilinear tent
   (1 - |dy|/4)(1 - |dx|/4) over the pixels within 3 rows and 3 columns; C = G + D_C.
3. The Bayer mosaic takes at each pixel its RGGB colour: the pixel's own value where the quad
   and the Bayer patterns agree on the colour, else the estimate of steps 1 and 2.

Every step is a fixed sequence of array operations: deterministic, vectorised. A pixel's value
depends on the mosaic within :data:`REACH_PX` pixels (the classifier's 4, then the colour
difference's 3 and that pixel's classifier); a capture images :data:`BORDER_PX` pixels of
scene round its chart, that reach and the Bayer demosaicker's, and crops them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .bayer import Bayer

__all__ = ["QuadBayer", "quad_bayer", "quad_mosaic", "remosaic", "REACH_PX", "BORDER_PX"]

#: Pixels of the quad mosaic a remosaicked pixel depends on, a side.
REACH_PX = 7
#: Output pixels of scene a full-size quad Bayer capture images round its chart and crops
#: after developing: the remosaic's reach and the Bayer demosaicker's (3), to a whole period
#: of the pattern (4), so that without a denoising filter the chart's first pixel is a red
#: block's top-left one.
BORDER_PX = 12
#: The bilinear tent of step 2 over offsets -3..3 pixels: 1 - |d|/4.
_TENT = 1.0 - np.abs(np.arange(-3, 4)) / 4.0


def quad_colors(shape) -> np.ndarray:
    """int, shape ``shape``: each pixel's colour in the quad pattern, 0 red, 1 green, 2 blue:
    the 2 x 2 block (i // 2, j // 2) takes the RGGB cell's colour of (i // 2 mod 2, j // 2
    mod 2)."""
    rows, cols = shape
    rb = (np.arange(rows) // 2 % 2)[:, None]
    cb = (np.arange(cols) // 2 % 2)[None, :]
    return rb + cb


def bayer_colors(shape) -> np.ndarray:
    """int, shape ``shape``: each pixel's colour in the RGGB pattern, 0 red, 1 green, 2 blue."""
    rows, cols = shape
    return (np.arange(rows) % 2)[:, None] + (np.arange(cols) % 2)[None, :]


def quad_mosaic(channels, shape) -> np.ndarray:
    """Each pixel's filter transmittance under the quad pattern, shape ``shape``, from
    ``channels`` (t_R, t_G, t_B)."""
    return np.asarray(channels, dtype=float)[quad_colors(shape)]


def _shifted(padded, pad, shape, dy, dx) -> np.ndarray:
    """The view of ``padded`` (the image with ``pad`` pixels round it) whose pixel (i, j) is
    the image's (i + dy, j + dx)."""
    rows, cols = shape
    return padded[pad + dy:pad + dy + rows, pad + dx:pad + dx + cols]


def _green(x, colors) -> np.ndarray:
    """Step 1: the green plane, the edge-directed estimate at red and blue pixels."""
    shape = x.shape
    pad = 4
    p = np.pad(x, pad, mode="edge")  # the border's values, finite, within the cropped border
    # the side of the block a pixel sits on: the near green neighbour is outside it
    left = (np.arange(shape[1]) % 2 == 0)[None, :]
    top = (np.arange(shape[0]) % 2 == 0)[:, None]
    near_h = np.where(left, _shifted(p, pad, shape, 0, -1), _shifted(p, pad, shape, 0, 1))
    far_h = np.where(left, _shifted(p, pad, shape, 0, 2), _shifted(p, pad, shape, 0, -2))
    near_v = np.where(top, _shifted(p, pad, shape, -1, 0), _shifted(p, pad, shape, 1, 0))
    far_v = np.where(top, _shifted(p, pad, shape, 2, 0), _shifted(p, pad, shape, -2, 0))
    g_h = (2.0 * near_h + far_h) / 3.0
    g_v = (2.0 * near_v + far_v) / 3.0
    delta_h = np.abs(near_h - far_h) + np.abs(
        2.0 * x - _shifted(p, pad, shape, 0, -4) - _shifted(p, pad, shape, 0, 4))
    delta_v = np.abs(near_v - far_v) + np.abs(
        2.0 * x - _shifted(p, pad, shape, -4, 0) - _shifted(p, pad, shape, 4, 0))
    estimate = np.where(delta_h < delta_v, g_h,
                        np.where(delta_v < delta_h, g_v, 0.5 * (g_h + g_v)))
    return np.where(colors == 1, x, estimate)


def _tent_sum(image) -> np.ndarray:
    """The sum of ``image`` (zero outside it) weighted by the separable tent over offsets -3..3."""
    out = np.zeros_like(image)
    p = np.pad(image, 3)
    for k, w in enumerate(_TENT):
        out += w * p[k:k + image.shape[0], 3:3 + image.shape[1]]
    rows = out
    out = np.zeros_like(image)
    p = np.pad(rows, 3)
    for k, w in enumerate(_TENT):
        out += w * p[3:3 + image.shape[0], k:k + image.shape[1]]
    return out


def remosaic(balanced) -> np.ndarray:
    """The RGGB Bayer mosaic of the same shape from a white-balanced quad mosaic
    (steps 1-3 of the module's description)."""
    x = np.asarray(balanced, dtype=float)
    if x.ndim != 2:
        raise ValueError(f"remosaic: a 2-D mosaic, got shape {x.shape}")
    colors = quad_colors(x.shape)
    green = _green(x, colors)
    target = bayer_colors(x.shape)
    out = np.where(target == 1, green, x)
    for c in (0, 2):
        mask = (colors == c).astype(float)
        difference = _tent_sum(mask * (x - green)) / _tent_sum(mask)
        estimate = green + difference
        out = np.where((target == c) & (colors != c), estimate, out)
    return out


@dataclass(frozen=True)
class QuadBayer(Bayer):
    """A quad Bayer sensor read full size and its development: the quad mosaic white-balanced,
    remosaicked (:func:`remosaic`) and developed as :class:`~epc_fast.simulate.bayer.Bayer`'s
    (its ``demosaic``, ``channels`` and ``weights``)."""

    @property
    def border_px(self) -> int:
        return BORDER_PX

    def mosaic(self, shape_out, binning: int) -> np.ndarray:
        """Each sensor pixel's filter transmittance under the quad pattern, shape
        ``shape_out`` (a full-size read: ``binning`` 1)."""
        if binning != 1:
            raise ValueError(f"QuadBayer: a full-size read (binning 1), got binning {binning!r}; "
                             "a quad Bayer sensor binned 2 x 2 is a Bayer sensor of twice the "
                             "pitch")
        return quad_mosaic(self.channels, shape_out)

    def luminance(self, raw_e) -> np.ndarray:
        """e- on the cell's scale: white balance (each pixel over its quad filter's
        transmittance), the remosaic, then the Bayer development
        (:meth:`~epc_fast.simulate.bayer.Bayer.developed`)."""
        raw = np.asarray(raw_e, dtype=float)
        return self.developed(remosaic(raw / self.mosaic(raw.shape, 1)))


def quad_bayer(sensor: Bayer) -> QuadBayer:
    """The quad Bayer sensor of ``sensor``'s demosaicker, channels and weights, read full
    size."""
    return QuadBayer(sensor.demosaic, sensor.channels, sensor.weights)
