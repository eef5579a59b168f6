"""The capture simulator: test charts captured by a design from the physics of the image, and
the measurements (ISO 12233 e-SFR, flat-patch SNR) that check the model against them."""

from .capture import Capture, capture
from .charts import Chart, flat, image, slanted_edge

__all__ = ["Capture", "capture", "Chart", "flat", "image", "slanted_edge"]
