"""A scan's space with every kind of reduction, and the check that two scans gave the same
numbers: shared by the runner's tests and the Dask backend's."""

import dataclasses

import numpy as np

from epc_fast.presets import HIGH_TIER
from epc_fast.scan import (Binned, FractionBelow, Grid, Histogram, LogNormal, LogUniform,
                           Quantiles, Space, Summary, TopK)

SPACE = Space(design=HIGH_TIER, illuminance_lux=LogUniform(10, 1e5),
              shake_deg_per_s=LogNormal(4.39, 0.5), read_noise_e=Grid((0.0, 2.0)))


def every_reduction() -> dict:
    """One of each kind, quantiles both exact and streamed, on two groupings."""
    return {"summary": Summary(by="design"),
            "histogram": Histogram(1e3, 1e7, 40, by="design"),
            "exact": Quantiles((0.05, 0.5, 0.95), by="design"),
            "streamed": Quantiles((0.05, 0.5, 0.95), by="design", exact_up_to=0),
            "bands": Quantiles((0.1, 0.9), exact_up_to=0, bins_per_decade=100,
                               by=("design", Binned("illuminance_lux",
                                                    tuple(np.geomspace(10, 1e5, 5))))),
            "below": FractionBelow(2e6, by=("design", "read_noise_e")),
            "best": TopK(5)}


def assert_same_numbers(a, b) -> None:
    """Every array and number of every reduction result is identical (NaN where NaN)."""
    assert a.results.keys() == b.results.keys()
    assert (a.points, a.partial, a.seed) == (b.points, b.partial, b.seed)
    for name in a.results:
        for field in dataclasses.fields(a.results[name]):
            x, y = getattr(a.results[name], field.name), getattr(b.results[name], field.name)
            if isinstance(x, dict):
                assert x.keys() == y.keys(), (name, field.name)
                pairs = [(x[k], y[k]) for k in x]
            else:
                pairs = [(x, y)]
            for u, v in pairs:
                assert np.array_equal(np.asarray(u), np.asarray(v),
                                      equal_nan=np.asarray(u).dtype.kind == "f"), (name, field.name)
