"""The NumPy reference implementation of the model, readable as the spec (docs/model.md).

:mod:`~epc_fast.reference.model` is the model, one formula a function (its MTF factors in
:mod:`~epc_fast.reference.mtf`, a lens table's in :mod:`~epc_fast.reference.lens`);
:mod:`~epc_fast.reference.sensitivity` what limits a design and how sensitive it is (the
shares and the elasticities); :mod:`~epc_fast.reference.optics` the lens's wavefront error and
denoising; :mod:`~epc_fast.reference.cfa` the demosaicker's MTF. Every function carries the same name as its C++ counterpart in
``cpp/include/epc_fast/``; the core is tested against them. The model's names are importable
from here (``epc_fast.reference.mtf_diffraction``).
"""

from __future__ import annotations

from . import cfa, lens, model, mtf, optics, sensitivity
from .model import *  # noqa: F401,F403  (the model's names, as its __all__ lists them)
from .model import __all__ as _model_names
from .optics import *  # noqa: F401,F403
from .optics import __all__ as _optics_names

__all__ = ["cfa", "lens", "model", "mtf", "optics", "sensitivity", *_model_names, *_optics_names]
