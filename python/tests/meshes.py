"""Meshes the Python tests build."""

import numpy as np


def grid_sheet(n, size, centred=False):
    """A flat square sheet in z = 0 of n x n quads (two triangles each), front +z: over
    [0, size]^2, or centred on the origin."""
    xs = np.linspace(-size / 2, size / 2, n + 1) if centred else np.linspace(0, size, n + 1)
    v = np.array([[x, y, 0.0] for y in xs for x in xs])
    f = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            f += [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
    return v, np.array(f)
