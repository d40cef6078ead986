"""Orientation of a flat panel and of the two sub-panels of a twofold panel.

Conventions follow pvlib: ``surface_tilt`` from horizontal, ``surface_azimuth`` clockwise from
north (180 = south). ``fold_angle`` is the dihedral angle between the two sub-panels: 180 is flat,
smaller is more folded; each sub-panel turns by ``(180 - fold_angle) / 2`` away from the flat
panel. The "east" sub-panel is the one turned toward the morning sun.

Two parametrisations of the twofold panel (foldopt SPEC, "Geometry"):

- ``azimuth-split`` (Shin et al. Sec. IV-B, Fig. 6): both sub-panels keep the base tilt and
  their azimuths split by -/+ (180 - fold_angle)/2; at 90 deg and azimuth 180 they face 135 and
  225 deg as in the paper.
- ``hinge`` (physical): each sub-panel normal is the flat normal rotated by -/+ (180 -
  fold_angle)/2 about the fold line, which lies in the panel plane along the up-slope direction.
  The angle between the two normals is then exactly ``180 - fold_angle`` and at zero tilt the
  panel is a ridge tent along the base azimuth.
"""

from __future__ import annotations

import numpy as np

from foldopt.names import FLAT_FOLD_ANGLE, GEOMETRIES


def _east_sign(surface_azimuth):
    # Turning toward azimuth - 90 faces east for panels facing the southern half of the sky and
    # west for those facing the northern half, so the east sub-panel turns the other way there.
    return np.where(np.cos(np.radians(surface_azimuth)) <= 0, 1.0, -1.0)


def normal_vector(surface_tilt, surface_azimuth):
    """Unit normal of surfaces in east-north-up coordinates.

    The same vector as the sun's for ``(solar_zenith, solar_azimuth)``, so that a dot product of
    the two is pvlib's ``irradiance.aoi_projection``.

    Parameters
    ----------
    surface_tilt : array_like
        Tilt from horizontal [deg] (or a zenith angle).
    surface_azimuth : array_like
        Azimuth clockwise from north [deg], broadcast against ``surface_tilt``.

    Returns
    -------
    numpy.ndarray
        Shape ``broadcast + (3,)``: east, north and up components [-].

    Examples
    --------
    Vertical surfaces facing east and south:

    >>> normal_vector(90.0, [90.0, 180.0]).round(12) + 0.0
    array([[ 1.,  0.,  0.],
           [ 0., -1.,  0.]])
    """
    tilt, azimuth = np.radians(surface_tilt), np.radians(surface_azimuth)
    sin_tilt = np.sin(tilt)
    return np.stack(
        np.broadcast_arrays(sin_tilt * np.sin(azimuth), sin_tilt * np.cos(azimuth), np.cos(tilt)),
        axis=-1,
    )


def orientation_from_normal(normal, level_azimuth=180.0):
    """``surface_tilt`` and ``surface_azimuth`` of east-north-up unit normals.

    The inverse of :func:`normal_vector`. A level surface has no azimuth; it gets
    ``level_azimuth`` so that formulas that read one anyway (Shin et al. Eq. 5) treat it like the
    panel it came from.

    Parameters
    ----------
    normal : array_like
        Unit normals, east, north and up on the last axis [-].
    level_azimuth : float or array_like, default 180
        Azimuth given to level surfaces [deg], broadcast against the normals' leading axes.

    Returns
    -------
    surface_tilt, surface_azimuth : numpy.ndarray
        [deg]; azimuth in [0, 360).
    """
    east, north, up = np.moveaxis(np.asarray(normal), -1, 0)
    tilt = np.degrees(np.arctan2(np.hypot(east, north), up))
    level = np.hypot(east, north) < 1e-12
    azimuth = np.where(level, level_azimuth, np.degrees(np.arctan2(east, north)) % 360.0)
    return tilt, azimuth


def subpanel_orientation(fold_angle, surface_tilt, surface_azimuth, geometry="hinge"):
    """Orientation of the east and west sub-panels of a twofold panel.

    Parameters
    ----------
    fold_angle : array_like
        Dihedral angle between the sub-panels [deg], in (0, 180]; 180 is flat.
    surface_tilt, surface_azimuth : array_like
        Orientation of the unfolded (flat) panel [deg], broadcast against ``fold_angle``.
    geometry : {'hinge', 'azimuth-split'}
        Parametrisation, see the module docstring.

    Returns
    -------
    dict
        ``surface_tilt_east``, ``surface_azimuth_east``, ``surface_tilt_west``,
        ``surface_azimuth_west`` [deg], each shaped as ``fold_angle``.

    Raises
    ------
    ValueError
        If ``geometry`` is not one of :data:`foldopt.names.GEOMETRIES`.

    References
    ----------
    .. [1] D. Shin, N. Chang, Y. Wang, M. Pedram, "Reconfigurable three dimensional photovoltaic
       panel architecture for solar-powered time extension", Sec. IV-B and Fig. 6 (azimuth-split).
    .. [2] O. Rodrigues, "Des lois geometriques qui regissent les deplacements d'un systeme solide
       dans l'espace", J. Math. Pures Appl. 5, 380-440, 1840: the rotation of a vector about a unit
       axis perpendicular to it, ``n cos(a) + (u x n) sin(a)`` (hinge).

    Examples
    --------
    Folded to 90 deg, the paper's sub-panels of a south-facing panel face 135 and 225 deg:

    >>> sides = subpanel_orientation(90.0, 34.05, 180.0, geometry="azimuth-split")
    >>> print(sides["surface_azimuth_east"], sides["surface_azimuth_west"])
    135.0 225.0

    With the hinge, the two normals stand ``180 - fold_angle`` = 90 deg apart:

    >>> sides = subpanel_orientation(90.0, 34.05, 180.0, geometry="hinge")
    >>> east = normal_vector(sides["surface_tilt_east"], sides["surface_azimuth_east"])
    >>> west = normal_vector(sides["surface_tilt_west"], sides["surface_azimuth_west"])
    >>> print(round(float(np.degrees(np.arccos(east @ west))), 6))
    90.0
    """
    fold_angle = np.asarray(fold_angle, dtype=float)
    turn = (FLAT_FOLD_ANGLE - fold_angle) / 2.0 * _east_sign(surface_azimuth)
    if geometry == "azimuth-split":
        shape = np.broadcast_shapes(turn.shape, np.shape(surface_tilt))
        tilt = np.broadcast_to(np.asarray(surface_tilt, dtype=float), shape).copy()
        turn = np.broadcast_to(turn, shape)
        return {
            "surface_tilt_east": tilt,
            "surface_azimuth_east": (surface_azimuth - turn) % 360.0,
            "surface_tilt_west": tilt.copy(),
            "surface_azimuth_west": (surface_azimuth + turn) % 360.0,
        }
    if geometry == "hinge":
        tilt, azimuth = np.radians(surface_tilt), np.radians(surface_azimuth)
        normal = normal_vector(surface_tilt, surface_azimuth)
        # Rodrigues' rotation of the normal about the up-slope unit vector u, which is
        # perpendicular to it: n' = n cos(a) + (u x n) sin(a). u x n is horizontal and points to
        # azimuth - 90; the limit tilt -> 0 keeps u along the base azimuth's back direction.
        up_slope = np.stack(
            np.broadcast_arrays(
                -np.cos(tilt) * np.sin(azimuth), -np.cos(tilt) * np.cos(azimuth), np.sin(tilt)
            ),
            axis=-1,
        )
        side = np.cross(up_slope, normal)
        angle = np.radians(turn)[..., None]
        east = normal * np.cos(angle) + side * np.sin(angle)
        west = normal * np.cos(angle) - side * np.sin(angle)
        surface_tilt_east, surface_azimuth_east = orientation_from_normal(east, surface_azimuth)
        surface_tilt_west, surface_azimuth_west = orientation_from_normal(west, surface_azimuth)
        return {
            "surface_tilt_east": surface_tilt_east,
            "surface_azimuth_east": surface_azimuth_east,
            "surface_tilt_west": surface_tilt_west,
            "surface_azimuth_west": surface_azimuth_west,
        }
    raise ValueError(f"geometry must be one of {', '.join(GEOMETRIES)}; got {geometry!r}")


def _angle_between(a, b):
    """Angle between unit vectors on the last axis [deg], exact near 0 and 180 (atan2 of the
    cross and dot products, not the arccos of a rounded dot product)."""
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1)))


def fold_from_planes(
    surface_tilt_1, surface_azimuth_1, surface_tilt_2, surface_azimuth_2, geometry="hinge"
):
    """The twofold panel that makes two given planes: the inverse of :func:`subpanel_orientation`.

    Both parametrisations give the two halves one tilt (the hinge's fold line runs up the slope,
    so the halves differ by a horizontal vector), so only planes of one tilt are made exactly; for
    others the nearest panel is returned and ``residual`` says how far it misses. The hinge's base
    normal is the bisector of the two normals and its fold angle 180 minus the angle between
    them; a level base (a ridge tent) takes the ridge's azimuth in [90, 270), the other end making
    the same planes. The azimuth-split's base azimuth is the middle of the shorter arc between
    the azimuths, its fold angle 180 minus that arc. Parallel planes are the flat panel (fold
    180) in the first plane's orientation. Which plane is the east half follows
    :func:`subpanel_orientation`.

    Parameters
    ----------
    surface_tilt_1, surface_azimuth_1, surface_tilt_2, surface_azimuth_2 : array_like
        The two planes [deg], broadcast against each other; their order is free.
    geometry : {'hinge', 'azimuth-split'}
        Parametrisation, see the module docstring.

    Returns
    -------
    dict
        ``surface_tilt``, ``surface_azimuth`` (the flat panel's) and ``fold_angle`` [deg], 0
        where no fold of the geometry short of 0 makes the planes (halves facing opposite ways,
        or azimuth-split azimuths 180 deg apart), the base then NaN for the hinge; ``first_east``
        (bool: the first plane is the east half); ``residual`` [deg], the larger angle between a
        given plane's normal and the panel's half made for it (NaN where the fold angle is 0).

    Raises
    ------
    ValueError
        If ``geometry`` is not one of :data:`foldopt.names.GEOMETRIES`.

    Examples
    --------
    Two 9 deg roofs facing 14 and 194 deg are a ridge tent along 104 deg, folded to 162 deg:

    >>> panel = fold_from_planes(9.0, 14.0, 9.0, 194.0)
    >>> [round(float(panel[key]), 9) for key in ("surface_tilt", "surface_azimuth", "fold_angle")]
    [0.0, 104.0, 162.0]
    """
    if geometry not in GEOMETRIES:
        raise ValueError(f"geometry must be one of {', '.join(GEOMETRIES)}; got {geometry!r}")
    tilt_1, azimuth_1, tilt_2, azimuth_2 = np.broadcast_arrays(
        *(
            np.asarray(value, dtype=float)
            for value in (surface_tilt_1, surface_azimuth_1, surface_tilt_2, surface_azimuth_2)
        )
    )
    first, second = normal_vector(tilt_1, azimuth_1), normal_vector(tilt_2, azimuth_2)
    between = _angle_between(first, second)
    parallel = between < 1e-9
    if geometry == "hinge":
        fold_angle = FLAT_FOLD_ANGLE - between
        bisector = first + second
        length = np.linalg.norm(bisector, axis=-1)
        opposite = length < 1e-12
        base = bisector / np.where(opposite, 1.0, length)[..., None]
        tilt, azimuth = orientation_from_normal(base, azimuth_1)
        tilt = np.where(tilt < 1e-9, 0.0, tilt)  # mirror images: a level base, not its rounding
        # The fold line runs up the slope, across the halves' horizontal difference: the base
        # azimuth is taken from that difference, which stays exact where the bisector's own
        # azimuth is lost in rounding (a base near level), on the side the bisector leans to.
        across = first - second
        ridge = np.degrees(np.arctan2(across[..., 0], across[..., 1])) % 180.0 + 90.0
        lean = base[..., 0] * np.sin(np.radians(ridge)) + base[..., 1] * np.cos(np.radians(ridge))
        ridge = np.where(lean < -1e-12, (ridge + 180.0) % 360.0, ridge)
        azimuth = np.where(parallel, azimuth, ridge)
        tilt = np.where(opposite, np.nan, tilt)
        azimuth = np.where(opposite, np.nan, azimuth)
        fold_angle = np.where(opposite, 0.0, fold_angle)
    else:
        # Level planes are parallel whatever their azimuths: the flat panel.
        arc = (azimuth_2 - azimuth_1 + 180.0) % 360.0 - 180.0  # in [-180, 180)
        tilt = (tilt_1 + tilt_2) / 2.0
        azimuth = np.where(parallel, azimuth_1, (azimuth_1 + arc / 2.0) % 360.0)
        fold_angle = np.where(parallel, FLAT_FOLD_ANGLE, FLAT_FOLD_ANGLE - np.abs(arc))
    residual, first_east = planes_residual(
        (tilt_1, azimuth_1, tilt_2, azimuth_2), fold_angle, tilt, azimuth, geometry
    )
    return {
        "surface_tilt": tilt,
        "surface_azimuth": azimuth,
        "fold_angle": fold_angle,
        "first_east": first_east,
        "residual": residual,
    }


def planes_residual(planes, fold_angle, surface_tilt, surface_azimuth, geometry="hinge"):
    """How far a twofold panel misses two given planes, in either order.

    Parameters
    ----------
    planes : tuple of array_like
        ``(surface_tilt_1, surface_azimuth_1, surface_tilt_2, surface_azimuth_2)`` [deg].
    fold_angle, surface_tilt, surface_azimuth : array_like
        The panel [deg] (:func:`subpanel_orientation`), broadcast against the planes.
    geometry : {'hinge', 'azimuth-split'}

    Returns
    -------
    residual : numpy.ndarray
        [deg]: the larger angle between a given plane's normal and the half made for it, the
        halves matched to the planes the nearer way; NaN where the fold angle is not in (0, 180]
        or the base is NaN.
    first_east : numpy.ndarray of bool
        Whether the first plane is the east half.
    """
    tilt_1, azimuth_1, tilt_2, azimuth_2 = planes
    fold_angle = np.asarray(fold_angle, dtype=float)
    folded = (fold_angle > 0.0) & (fold_angle <= FLAT_FOLD_ANGLE)
    made = subpanel_orientation(
        np.where(folded, fold_angle, FLAT_FOLD_ANGLE),
        np.nan_to_num(surface_tilt),
        np.nan_to_num(surface_azimuth),
        geometry,
    )
    first, second = normal_vector(tilt_1, azimuth_1), normal_vector(tilt_2, azimuth_2)
    east = normal_vector(made["surface_tilt_east"], made["surface_azimuth_east"])
    west = normal_vector(made["surface_tilt_west"], made["surface_azimuth_west"])
    as_made = np.maximum(_angle_between(first, east), _angle_between(second, west))
    swapped = np.maximum(_angle_between(first, west), _angle_between(second, east))
    defined = folded & np.isfinite(surface_tilt) & np.isfinite(surface_azimuth)
    return np.where(defined, np.minimum(as_made, swapped), np.nan), as_made <= swapped
