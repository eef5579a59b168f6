"""The transfers of moving and averaging the image, computed by quadrature of shifted copies,
against the closed forms they must equal (and, for the camera's turn, a direct integral)."""

import math

import numpy as np
import pytest
from scipy import integrate

from epc_fast.simulate import blur

F = np.linspace(0.0, 700.0, 701)


@pytest.mark.parametrize("width_mm", [0.0005, 0.0028, 0.01])
def test_the_aperture_integral_is_a_sinc(width_mm):
    # The average over a square's side of exp(-2 pi i f x) is sinc(w f); Gauss-Legendre with
    # 2 nodes a cycle plus 16 is exact to rounding.
    assert np.max(np.abs(blur.aperture_transfer(F, width_mm) - np.sinc(width_mm * F))) < 1e-12


@pytest.mark.parametrize("sigma_mm", [0.0002, 0.001, 0.005])
def test_jitter_is_a_gaussian_where_it_passes_anything(sigma_mm):
    got = blur.jitter_transfer(F, sigma_mm)
    want = np.exp(-2 * np.pi ** 2 * sigma_mm ** 2 * F ** 2)
    inside = F * sigma_mm <= 0.9
    assert np.max(np.abs(got[inside] - want[inside])) < 1e-12
    assert np.all(got[~inside] == 0.0) and np.all(want[~inside] < 1e-6)
    assert np.all(blur.jitter_transfer(F, 0.0) == 1.0)


def test_a_short_turn_is_a_uniform_motion():
    omega = math.radians(4.39)
    t = 0.01
    h, extent, mean = blur.motion_transfer(F, t, 5.6, omega)
    b = 5.6 * math.tan(omega * t)
    assert extent == pytest.approx(b, rel=1e-15)
    # Over 0.044 degrees the tangent's speed varies by 6e-7: the motion is a box of length b.
    assert np.max(np.abs(np.abs(h) - np.abs(np.sinc(b * F)))) < 1e-6
    assert mean == pytest.approx(b / 2, rel=1e-6)


@pytest.mark.parametrize("t_s", [0.5, 3.0])
def test_a_long_turn_is_the_time_average_of_the_moving_image(t_s):
    omega = math.radians(4.39)
    f = np.array([0.3, 1.0, 2.5, 7.0])
    h, extent, mean = blur.motion_transfer(f, t_s, 5.6, omega)

    def direct(fi, part):
        g = lambda t: np.exp(-2j * np.pi * fi * (5.6 * np.tan(omega * t) - mean))
        return integrate.quad(lambda t: getattr(g(t), part), 0, t_s, limit=500)[0] / t_s

    want = np.array([direct(fi, "real") + 1j * direct(fi, "imag") for fi in f])
    # The composite Gauss-Legendre rule against adaptive quadrature to 1e-10.
    assert np.max(np.abs(h - want)) < 1e-9
    # The camera's turn is not a uniform motion: its transfer differs from sinc(b f).
    assert np.max(np.abs(np.abs(h) - np.abs(np.sinc(extent * f)))) > 1e-4 * (t_s > 1)


def test_no_turn_no_motion():
    h, extent, mean = blur.motion_transfer(F, 0.0, 5.6, 0.1)
    assert np.all(h == 1.0) and extent == 0.0 and mean == 0.0


@pytest.mark.parametrize("angle_deg", [0.0, 5.0, -30.0, 90.0])
def test_a_motion_in_any_direction_is_the_motion_at_the_frequency_along_it(angle_deg):
    # On the grid (fy, fx) the image moving along (cos a, sin a) has the factor of the 1-D
    # motion at u = fx cos a + fy sin a: the matrix product of rows' and columns' phases
    # against motion_transfer summed point by point, to rounding (a 3 s turn: a long path).
    fy, fx = np.linspace(-400.0, 400.0, 33), np.linspace(0.0, 500.0, 21)
    a = math.radians(angle_deg)
    got = blur.motion_transfer_2d(fy, fx, 3.0, 5.6, math.radians(4.39), a, start_s=0.5)
    u = fx[None, :] * math.cos(a) + fy[:, None] * math.sin(a)
    want = blur.motion_transfer(u, 3.0, 5.6, math.radians(4.39), start_s=0.5)[0]
    assert got.shape == (33, 21)
    assert np.max(np.abs(got - want)) < 1e-12
    assert np.max(np.abs(got)) > 0.99 and np.min(np.abs(got)) < 0.05  # it blurs, not all
    assert np.all(blur.motion_transfer_2d(fy, fx, 0.0, 5.6, 0.1, a) == 1.0)
