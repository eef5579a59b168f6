"""Measurements made by hand, for the tests of the front, the tables and the plot of speed
against accuracy."""

from epc_fast.tradeoff import Accuracy, Measurement, Setting


def measurement(name, max_error, speed_2_threads, spectrum_samples=None):
    return Measurement(Setting(name, {}, spectrum_samples), "halley", 1e-14, "float64",
                       Accuracy(max_error, max_error / 10, 100, 0),
                       {1: speed_2_threads / 2, 2: speed_2_threads})
