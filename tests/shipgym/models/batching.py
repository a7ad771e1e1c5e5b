"""A model's batched numpy evaluation against one ship at a time."""

from __future__ import annotations

import numpy as np

from shipgym.models.base import ShipModel


def assert_columns_are_ships(
    model: ShipModel,
    x: np.ndarray,
    u: np.ndarray,
    w: np.ndarray,
    p: np.ndarray,
    h: float | None = None,
) -> None:
    """``model``'s rhs over the columns of x, u, w, p (one ship each) has shape (n_x, N) and
    equals each column's own rhs; with ``h`` [s] the RK4 step too."""
    f = model.f_numpy(x, u, w, p)
    assert f.shape == x.shape == (model.n_states, p.shape[1])
    ships = [(x[:, j], u[:, j], w[:, j], p[:, j]) for j in range(x.shape[1])]
    for j, ship in enumerate(ships):
        np.testing.assert_allclose(f[:, j], model.f_numpy(*ship), rtol=1e-14, atol=0)
    if h is not None:
        steps = model.step_numpy(x, u, w, p, h)
        for j, ship in enumerate(ships):
            np.testing.assert_allclose(
                steps[:, j], model.step_numpy(*ship, h), rtol=1e-14, atol=1e-15
            )
