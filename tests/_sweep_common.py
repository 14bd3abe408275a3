"""Shared small sweep settings: every default sweep test uses the same static config and chunk
shape so the vmapped solve compiles once per test session."""

import numpy as np

VALUES = np.array([12.0, 14.0, 17.0, 19.0])
KW = dict(transient_periods=3, sample_periods=4, rtol=1e-8, atol=1e-10, max_steps=4000, chunk_size=4)
