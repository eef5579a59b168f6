"""The capture simulator: test charts captured by a design from the physics of the image,
and the measurements that check the model against them: the slanted-edge e-SFR of
ISO 12233:2017 (:mod:`~epc_fast.simulate.edge_sfr`) and the SNR of a flat patch
(:mod:`~epc_fast.simulate.flat_patch`);
a Siemens star (:mod:`~epc_fast.simulate.star`) and the design review's pictures: a contact
sheet and the edges' MTF against the model's (:mod:`~epc_fast.simulate.review`,
:mod:`~epc_fast.simulate.plot`)."""

from .camera import Capture, capture
from .charts import Chart, flat, image, slanted_edge
from .edge_sfr import EdgeSFR, esfr, mtf50
from .flat_patch import FlatSNR, snr
from .star import siemens_star, star_size_px

__all__ = ["Capture", "capture", "Chart", "flat", "image", "slanted_edge", "EdgeSFR", "esfr",
           "mtf50", "FlatSNR", "snr", "siemens_star", "star_size_px"]
