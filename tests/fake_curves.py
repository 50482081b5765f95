"""A model curve of closed form whose shape depends on beta: fast tests of a fit's logic (the
``closed_form`` fixture of conftest.py puts it in place of the fit's model curves)."""

import numpy as np


class FakeCurve:
    def __init__(self, scene, deltas):
        self.scene, self.delta = scene, np.asarray(deltas, float)
        self.force = self.delta ** (1.3 + 20 * scene.beta) * (1 + scene.beta)
        self.stop_reason, self.solutions = "closed form", []

    def __len__(self):
        return self.delta.size
