"""The twofold panel as pvlib objects, for users of ``pvlib.modelchain.ModelChain``.

This module owns :func:`twofold_arrays`: the two sub-panels of a panel folded at a dihedral
``fold_angle`` as two ``pvlib.pvsystem.Array`` on fixed mounts, each of its own orientation
(:func:`foldopt.physics.geometry.subpanel_orientation`), so that a folded panel is one ``PVSystem``
whose per-array results are the sub-panels'. It adds no physics of its own.
"""

from __future__ import annotations

import math

from pvlib.pvsystem import Array, FixedMount

from foldopt.physics.geometry import subpanel_orientation
from foldopt.names import FLAT_FOLD_ANGLE, GEOMETRIES, canonical


def twofold_arrays(
    fold_angle,
    surface_tilt,
    surface_azimuth,
    geometry="hinge",
    *,
    module_parameters=None,
    temperature_model_parameters=None,
    modules_per_string=2,
    strings=1,
    name_prefix="",
    **array_kwargs,
):
    """The east and west sub-panels of a twofold panel as pvlib ``Array`` objects.

    The panel of ``modules_per_string`` modules in each of ``strings`` strings is folded along
    its middle into two equal sub-panels [1]_; each becomes an ``Array`` of half the modules
    per string on a ``FixedMount`` [2]_ [3]_ of its own tilt and azimuth.

    Parameters
    ----------
    fold_angle : float
        Dihedral angle between the two sub-panels [deg], in (0, 180]; 180 is the flat panel.
    surface_tilt, surface_azimuth : float
        Orientation of the unfolded panel [deg], pvlib's conventions: tilt from horizontal,
        azimuth clockwise from north (180 = south).
    geometry : {'hinge', 'azimuth-split'}, default 'hinge'
        How the sub-panels turn (see :mod:`foldopt.physics.geometry`): ``hinge`` rotates each normal by
        ``(180 - fold_angle) / 2`` about the fold line; ``azimuth-split`` keeps the tilt and
        splits the azimuths by that angle (Shin et al. Fig. 6).
    module_parameters, temperature_model_parameters : dict, optional
        Passed to both ``Array`` objects (pvlib's meaning and units).
    modules_per_string : int, default 2
        Modules per string of the whole panel: even, at least 2; each sub-panel gets half.
    strings : int, default 1
        Parallel strings of each sub-panel.
    name_prefix : str, default ''
        The arrays are named ``name_prefix + 'east'`` and ``name_prefix + 'west'``.
    **array_kwargs
        Further ``pvlib.pvsystem.Array`` arguments for both, e.g. ``albedo`` (pvlib's default is
        0.25, foldopt's studies' 0.2) or ``module_type``.

    Returns
    -------
    tuple of pvlib.pvsystem.Array
        ``(east, west)``: the sub-panel turned toward the morning sun first.

    Raises
    ------
    ValueError
        If ``fold_angle`` is outside (0, 180], ``geometry`` is unknown or ``modules_per_string``
        is odd or less than 2.

    References
    ----------
    .. [1] D. Shin, N. Chang, Y. Wang, M. Pedram, "Reconfigurable three dimensional photovoltaic
       panel architecture for solar-powered time extension", 2015, Sec. IV-B and Fig. 6.
    .. [2] pvlib ``pvsystem.Array``,
       https://pvlib-python.readthedocs.io/en/stable/reference/generated/pvlib.pvsystem.Array.html
    .. [3] pvlib ``pvsystem.FixedMount``,
       https://pvlib-python.readthedocs.io/en/stable/reference/generated/pvlib.pvsystem.FixedMount.html

    Examples
    --------
    A panel of two 120 W modules folded to 30 deg at Los Angeles, on a clear day:

    >>> import pandas as pd, pvlib, foldopt
    >>> system = pvlib.pvsystem.PVSystem(
    ...     arrays=foldopt.twofold_arrays(
    ...         30, 34.05, 180, module_parameters={"pdc0": 120, "gamma_pdc": -0.004},
    ...         temperature_model_parameters=pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS[
    ...             "sapm"]["open_rack_glass_glass"]),
    ...     inverter_parameters={"pdc0": 240})
    >>> location = pvlib.location.Location(34.05, -118.25, "America/Los_Angeles")
    >>> times = pd.date_range("2014-09-23", periods=96, freq="15min", tz=location.tz)
    >>> mc = pvlib.modelchain.ModelChain.with_pvwatts(system, location)
    >>> mc = mc.run_model(location.get_clearsky(times))
    >>> east, west = mc.results.total_irrad  # per sub-panel; mc.results.ac is the panel's
    """
    fold = float(fold_angle)
    if not 0.0 < fold <= FLAT_FOLD_ANGLE:
        raise ValueError(f"fold_angle must be in (0, 180] deg (180 is flat); got {fold_angle!r}")
    try:
        name = canonical(geometry, GEOMETRIES)
        if name not in GEOMETRIES:  # canonical passes what is not a string through
            raise ValueError(f"must be one of {', '.join(GEOMETRIES)}")
    except ValueError as error:
        raise ValueError(f"geometry = {geometry!r}: {error}") from None
    if (
        isinstance(modules_per_string, bool)
        or not isinstance(modules_per_string, int)
        or modules_per_string < 2
        or modules_per_string % 2
    ):
        raise ValueError(
            "modules_per_string must be an even integer of at least 2 (the panel's "
            f"modules, split evenly between the two sub-panels); got {modules_per_string!r}"
        )
    sides = subpanel_orientation(fold, float(surface_tilt), float(surface_azimuth), name)
    arrays = []
    for side in ("east", "west"):
        tilt, azimuth = (
            float(sides[f"surface_tilt_{side}"]),
            float(sides[f"surface_azimuth_{side}"]),
        )
        if not (math.isfinite(tilt) and math.isfinite(azimuth)):
            raise ValueError(
                f"surface_tilt and surface_azimuth must be finite; got {surface_tilt!r}, "
                f"{surface_azimuth!r}"
            )
        arrays.append(
            Array(
                FixedMount(surface_tilt=tilt, surface_azimuth=azimuth),
                module_parameters=module_parameters,
                temperature_model_parameters=temperature_model_parameters,
                modules_per_string=modules_per_string // 2,
                strings=strings,
                name=f"{name_prefix}{side}",
                **array_kwargs,
            )
        )
    return tuple(arrays)
