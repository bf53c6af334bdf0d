"""Tests of the section helpers on sampled signals."""

import math

import numpy as np

from chaoscam.analysis import crossing_section, local_maxima


def test_local_maxima_of_a_sine_are_exact_to_third_order():
    """Maxima of sin(t) sampled at dt = 0.05 are at π/2 + 2πk with value 1 (error < 1e-4)."""
    dt = 0.05
    x = np.sin(np.arange(0, 60, dt))
    times, values = local_maxima(x, dt)
    k = np.round((times - math.pi / 2) / (2 * math.pi))
    assert np.allclose(times, math.pi / 2 + 2 * math.pi * k, atol=1e-3)
    assert np.allclose(values, 1.0, atol=1e-4)


def test_crossing_section_of_a_circle():
    """Upward crossings of y = 0 on (cos t, sin t) are at t = 2πk with x = 1 (error < 1e-7)."""
    t = np.arange(0.0, 40.0, 0.05)
    states = np.column_stack([np.cos(t), np.sin(t)])
    times, pts = crossing_section(t, states, index=1, level=0.0, direction=1)
    assert times.size == 6
    assert np.allclose(np.mod(times + 1.0, 2 * math.pi) - 1.0, 0.0, atol=1e-7)
    assert np.allclose(pts[:, 0], 1.0, atol=1e-7)


def test_crossing_directions():
    """Direction -1 finds the downward crossings only, 0 both kinds."""
    t = np.arange(0.0, 40.0, 0.05)
    states = np.column_stack([np.cos(t), np.sin(t)])
    down, _ = crossing_section(t, states, index=1, direction=-1)
    both, _ = crossing_section(t, states, index=1, direction=0)
    assert np.allclose(np.mod(down, 2 * math.pi), math.pi, atol=1e-7)
    assert both.size == down.size + 6
