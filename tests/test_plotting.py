"""Figure helpers: colour choices that carry meaning."""

import numpy as np

from jaxcelt.plotting.bifurcation import _lyapunov_bins


def test_lyapunov_bins_separate_signs():
    # exponents within +-band are neutral grey; clearly negative ones blue, positive ones warm
    # (the earlier continuous map made |lambda| < 0.2 look white -- unreadable on white paper)
    lam = np.array([-2.0, -0.1, 0.0, 0.01, 0.1, 0.8, 3.0])
    cmap, norm, bounds = _lyapunov_bins(lam, 0.02)
    rgb = np.array([cmap(norm(x))[:3] for x in lam])
    grey = np.array(cmap(norm(0.0))[:3])
    assert np.allclose(rgb[3], grey) and np.allclose(np.ptp(grey), 0.0)  # 0.01 is neutral, grey is grey
    assert rgb[1][2] > rgb[1][0] and rgb[0][2] > rgb[0][0]  # negatives: blue dominates red
    assert all(rgb[i][0] > rgb[i][2] for i in (4, 5, 6))  # positives: red dominates blue
    assert bounds[0] <= lam.min() and bounds[-1] >= lam.max()  # every value inside the colour bar
