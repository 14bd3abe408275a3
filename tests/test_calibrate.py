"""Calibration of the Pade laws to the Hertz integral law."""

import numpy as np
import pytest

from jaxcelt.physics.contact.calibrate import calibrate, integral_reference, slip_samples
from jaxcelt.physics.contact.integral import patch_integrals
from jaxcelt.studies.ladder import HERTZ_CALIBRATED


def test_reference_uses_linearity_in_d():
    s = slip_samples(n_alpha=3, n_beta=2, n_gamma=2)
    ref = np.asarray(integral_reference(s, 0.1813))
    for i in (0, 5, 11):
        direct = np.array(
            patch_integrals(s.vsx[i], s.vsy[i], s.omega_s[i], 0.1813, s.d_c[i], s.d_s[i], n_angle=32, n_radial=16)
        )
        np.testing.assert_allclose(ref[i], direct, atol=1e-12)


def test_generalised_beats_pade_small_grid():
    # the paper's claim: the generalised approximant (free exponents) fits the integral law better
    s = slip_samples(n_alpha=9, n_beta=8, n_gamma=2)
    ref = integral_reference(s, 0.1813)
    gp = calibrate("generalised_pade", samples=s, reference=ref)
    pd = calibrate("pade", samples=s, reference=ref)
    assert gp.rms < gp.rms_start and pd.rms < pd.rms_start
    assert gp.rms < 0.6 * pd.rms


@pytest.mark.slow
def test_default_calibration_reproduces_stored_constants():
    c = calibrate("generalised_pade")
    for k, v in HERTZ_CALIBRATED["generalised_pade"].items():
        assert abs(c.values[k] - v) < 1e-3 * max(1, abs(v))
    assert c.rms < 0.035
