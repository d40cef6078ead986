"""Each surface's view of the sky over a sky's blocks: the factors of the isotropic and the
horizon-band diffuse terms, the same for the kernel and the reference path.

On an open plain the factors are ``(1 + cos tilt) / 2`` and ``sin tilt``, computed here with the
arithmetic the kernel always used, so that a study without a horizon gives the same bits. Where a
block's site has a horizon (:attr:`foldopt.engine.sky.Sky.horizon_of`), both are reduced by what
it hides of the sky dome (:func:`foldopt.physics.horizon.sky_view_factors`); the ground-reflected
term is left as it is.

The module may import numpy, :mod:`foldopt.physics` and :mod:`foldopt.engine.sky`.
"""

from __future__ import annotations

import numpy as np

from foldopt.engine.sky import Sky
from foldopt.physics.horizon import sky_view_factors

#: Tracker orientations are rounded to this [deg] before their views are worked out once per
#: distinct orientation (a year of 1-min steps has some 5e5): the factors change by less than
#: 1e-4 over it.
TRACKER_ROUNDING_DEG = 0.01


def open_views(cos_tilt):
    """The factors on an open plain: ``(1 + cos tilt) / 2`` and ``sin tilt`` [-], as arrays."""
    cos_tilt = np.asarray(cos_tilt, dtype=float)
    return (1.0 + cos_tilt) * 0.5, np.sqrt(np.maximum(1.0 - cos_tilt * cos_tilt, 0.0))


def surface_views(sky: Sky, blocks, surface_tilt, surface_azimuth, cos_tilt):
    """The factors of surfaces over selected blocks, or None where no selected block has a horizon.

    Parameters
    ----------
    sky : Sky
    blocks : slice or array_like
        The selected blocks, as :func:`foldopt.engine.evaluation.poa` takes them.
    surface_tilt, surface_azimuth : numpy.ndarray
        [deg], broadcast against the selected blocks' (n_selected, n_steps): one row per block, or
        k rows over one selected block.
    cos_tilt : numpy.ndarray
        The surfaces' cosine of tilt, as the caller computed it (the open plain's factors from it).

    Returns
    -------
    tuple of numpy.ndarray or None
        ``(isotropic, band)``, the broadcast shape of the surfaces.
    """
    if sky.horizon_of is None:
        return None
    of = np.atleast_1d(sky.horizon_of[blocks])
    if (of < 0).all():
        return None
    tilt, azimuth, cos_tilt = np.broadcast_arrays(
        np.asarray(surface_tilt, float),
        np.asarray(surface_azimuth, float),
        np.asarray(cos_tilt, float),
    )
    iso, band = (np.array(factor) for factor in open_views(cos_tilt))
    per_row = of if of.size == tilt.shape[0] else np.full(tilt.shape[0], of[0])
    for k in np.unique(per_row[per_row >= 0]):
        rows = per_row == k
        iso[rows], band[rows] = _views(tilt[rows], azimuth[rows], sky.horizons[k])
    return iso, band


def row_views(sky: Sky, row_block, normals, orientation, row_orientation) -> np.ndarray:
    """The kernel's ``row_view``: (n_rows, 2, 2) factors per row and sub-panel.

    Parameters
    ----------
    sky : Sky
    row_block : numpy.ndarray
        (n_rows,) block of each row.
    normals : numpy.ndarray
        (n_orientations, 2, 3) the sub-panels' unit normals (east, west).
    orientation : numpy.ndarray
        (n_orientations, 4) east tilt, east azimuth, west tilt, west azimuth [deg].
    row_orientation : numpy.ndarray
        (n_rows,) orientation of each row.

    Returns
    -------
    numpy.ndarray
    """
    # On an open plain the factors are the orientation's: worked out once each, then per row.
    views = np.empty((orientation.shape[0], 2, 2))
    for side in (0, 1):
        views[:, side, 0], views[:, side, 1] = open_views(normals[:, side, 2])
    views = np.take(views, row_orientation, axis=0)  # (fancy indexing costs some five times more)
    if sky.horizon_of is not None:
        of = sky.horizon_of[row_block]
        for k in np.unique(of[of >= 0]):
            rows = of == k
            taken = orientation[row_orientation[rows]]
            for side in (0, 1):
                views[rows, side, 0], views[rows, side, 1] = _views(
                    taken[:, 2 * side], taken[:, 2 * side + 1], sky.horizons[k]
                )
    return views


def _views(tilt, azimuth, profile):
    """:func:`sky_view_factors` once per distinct orientation (rounded for many, as a tracker's)."""
    tilt, azimuth = np.asarray(tilt, dtype=float), np.asarray(azimuth, dtype=float)
    if tilt.size <= 4096:
        return sky_view_factors(tilt, azimuth, *profile)
    pairs = np.round(
        np.stack([tilt.ravel(), azimuth.ravel() % 360.0], axis=1) / TRACKER_ROUNDING_DEG
    )
    unique, inverse = np.unique(pairs, axis=0, return_inverse=True)
    iso, band = sky_view_factors(
        unique[:, 0] * TRACKER_ROUNDING_DEG, unique[:, 1] * TRACKER_ROUNDING_DEG, *profile
    )
    inverse = inverse.ravel()
    return iso[inverse].reshape(tilt.shape), band[inverse].reshape(tilt.shape)
