"""The clear sky and its diffuse terms at every lit step in one compiled pass (numba).

A map's sky is pvlib's Ineichen clear sky [1]_ [2]_ with Kasten & Young's air mass [3]_ and the
diffuse light as the four orientation-free terms of
:func:`foldopt.physics.irradiance.sky_diffuse_terms` (isotropic, Hay & Davies [4]_ or Perez [5]_).
As NumPy calls they are some forty passes over every step of a year, night included: on
``bench/map.py --w5 --phases`` they were a quarter of a land site's sky. :func:`ineichen_terms` does
the same arithmetic once per step with the sun up, in one loop, and writes the arrays the engine
reads. It is pvlib's formulas, not new ones: ``tests/test_clearsky.py`` holds it to
``pvlib.clearsky.ineichen`` (with ``pvlib.atmosphere``'s air masses) and
:func:`foldopt.physics.irradiance.sky_diffuse_terms` on random sites, days and turbidities.

The formulas, as pvlib writes them (z the apparent zenith, AM the relative and AMa the absolute
air mass, TL the Linke turbidity, h the altitude [m], I0 the extraterrestrial irradiance):

- ``AM = 1 / (cos z + 0.50572 (96.07995 - z)^-1.6364)`` [3]_ Eq. 3, and
  ``AMa = AM p / 101325`` with ``p = 100 ((44331.514 - h) / 11880.516)^(1 / 0.1902632)`` (pvlib
  ``atmosphere.alt2pres``);
- ``GHI = cg1 I0 cos z exp(-cg2 AMa (fh1 + fh2 (TL - 1)))``, ``fh1 = exp(-h / 8000)``,
  ``fh2 = exp(-h / 1250)``, ``cg1 = 5.09e-5 h + 0.868``, ``cg2 = 3.92e-5 h + 0.0387`` [1]_ Eq. 1;
- ``DNI = min(I0 b exp(-0.09 AMa (TL - 1)), GHI (1 - (0.1 - 0.2 exp(-TL)) / (0.1 + 0.882 / fh1)) / cos z)``
  with ``b = 0.664 + 0.163 / fh1`` [1]_ Eq. 4 and [2]_, and ``DHI = GHI - DNI cos z``;
- the Perez terms: sky clearness ``eps = ((DHI + DNI) / DHI + k z^3) / (1 + k z^3)``, k = 1.041
  rad^-3, brightness ``delta = DHI AM / I0``, ``F1 = max(f11 + f12 delta + f13 z, 0)``,
  ``F2 = f21 + f22 delta + f23 z`` with the coefficients of eps's bin [5]_ Eq. 9 and Table 6
  (pvlib's ``allsitescomposite1990``); ``iso = DHI (1 - F1)``, ``circ = DHI F1 / max(cos z,
  cos 85 deg)``, ``hor = DHI F2``; Hay & Davies: ``A = DNI / I0``, ``iso = DHI max(1 - A, 0)``,
  ``circ = DHI A / max(cos z, 0.01745)``; ``ground = GHI albedo``.

References
----------
.. [1] P. Ineichen, R. Perez, "A new airmass independent formulation for the Linke turbidity
   coefficient", Solar Energy 73(3), 151-157, 2002 (pvlib ``clearsky.ineichen``).
.. [2] R. Perez et al., "A new operational model for satellite-derived irradiances: description
   and validation", Solar Energy 73(5), 307-317, 2002.
.. [3] F. Kasten, A. T. Young, "Revised optical air mass tables and approximation formula",
   Applied Optics 28(22), 4735-4738, 1989, Eq. 3.
.. [4] J. E. Hay, J. A. Davies, "Calculations of the solar radiation incident on an inclined
   surface", Proc. First Canadian Solar Radiation Data Workshop, 59-72, 1980.
.. [5] R. Perez, P. Ineichen, R. Seals, J. Michalsky, R. Stewart, "Modeling daylight availability
   and irradiance components from direct and global irradiance", Solar Energy 44(5), 271-289,
   1990, Eq. 9 and Table 6.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from foldopt import names
from foldopt.physics.irradiance import (
    CLEARNESS_EDGES,
    HAYDAVIES_COS_FLOOR,
    PEREZ_COS_FLOOR,
    PEREZ_KAPPA,
    perez_coefficients,
)

#: Transpositions by their code in the compiled loop (``none``: no diffuse terms).
TRANSPOSITION_CODES = {"none": 0, "isotropic": 1, "haydavies": 2, "perez": 3}
STANDARD_PRESSURE = 101325.0  # [Pa]
_EDGES = np.array(CLEARNESS_EDGES)  # an array, as the compiled loop takes a global


@njit(cache=True, error_model="numpy")
def _ineichen_terms(
    apparent_zenith,
    dni_extra,
    linke_turbidity,
    altitude,
    code,
    albedo,
    f1c,
    f2c,
    dni,
    ghi,
    dhi,
    terms,
):
    """The loop of :func:`ineichen_terms` over blocks and steps; writes 0 where the sun is down
    (the arrays come uninitialised: zeroing them first is a pass over every step).
    ``error_model="numpy"``: no division or power of the lit steps is by zero (their cosine is
    positive, their air mass finite), and Python's check of each would cost the loop a branch."""
    n_blocks, n_steps = apparent_zenith.shape
    for b in range(n_blocks):
        h = altitude[b]
        fh1 = math.exp(-h / 8000.0)
        fh2 = math.exp(-h / 1250.0)
        cg1 = 5.09e-05 * h + 0.868
        cg2 = 3.92e-05 * h + 0.0387
        pressure_ratio = (
            100.0 * ((44331.514 - h) / 11880.516) ** (1.0 / 0.1902632) / STANDARD_PRESSURE
        )
        b_coefficient = 0.664 + 0.163 / fh1
        correction_base = 0.1 + 0.882 / fh1
        # The turbidity's own terms, worked out again only where it changes (a block's day
        # takes one or two values: its UTC days'), the same operations on the same values.
        tl = math.nan
        above_one = turbid = correction = 0.0
        for s in range(n_steps):
            z = apparent_zenith[b, s]
            if not z < 90.0:
                dni[b, s] = ghi[b, s] = dhi[b, s] = 0.0
                for k in range(terms.shape[1]):
                    terms[b, k, s] = 0.0
                continue
            if linke_turbidity[b, s] != tl:
                tl = linke_turbidity[b, s]
                above_one = tl - 1.0
                turbid = fh1 + fh2 * above_one
                correction = 1.0 - (0.1 - 0.2 * math.exp(-tl)) / correction_base
            z_rad = math.radians(z)
            cos_z = math.cos(z_rad)
            airmass = 1.0 / (cos_z + 0.50572 * (6.07995 + (90.0 - z)) ** -1.6364)
            absolute = airmass * pressure_ratio
            extra = dni_extra[b, s]
            g = cg1 * extra * cos_z * max(math.exp(-cg2 * absolute * turbid), 0.0)
            beam = extra * max(b_coefficient * math.exp(-0.09 * absolute * above_one), 0.0)
            capped = g * min(max(correction / cos_z, 0.0), 1e20)
            d = min(beam, capped)
            diffuse = g - d * cos_z
            dni[b, s], ghi[b, s], dhi[b, s] = d, g, diffuse
            if code == 0:
                continue
            iso = circ = hor = 0.0
            if code == 1:
                iso = diffuse
            elif code == 2:
                anisotropy = d / extra
                iso = diffuse * max(1.0 - anisotropy, 0.0)
                circ = diffuse * anisotropy / max(cos_z, HAYDAVIES_COS_FLOOR)
            elif diffuse != 0.0:
                kappa_z3 = PEREZ_KAPPA * (z_rad * z_rad * z_rad)
                eps = ((diffuse + d) / diffuse + kappa_z3) / (1.0 + kappa_z3)
                k = -1
                for edge in _EDGES:
                    k += eps >= edge
                if k >= 0:
                    delta = diffuse * airmass / extra
                    f1 = max(f1c[k, 0] + f1c[k, 1] * delta + f1c[k, 2] * z_rad, 0.0)
                    f2 = f2c[k, 0] + f2c[k, 1] * delta + f2c[k, 2] * z_rad
                    iso = diffuse * (1.0 - f1)
                    circ = diffuse * f1 / max(cos_z, PEREZ_COS_FLOOR)
                    hor = diffuse * f2
            terms[b, 0, s], terms[b, 1, s], terms[b, 2, s], terms[b, 3, s] = (
                iso,
                circ,
                hor,
                g * albedo,
            )


def ineichen_terms(
    apparent_zenith,
    dni_extra,
    linke_turbidity,
    altitude,
    transposition: str = "perez",
    albedo: float = 0.2,
):
    """pvlib's Ineichen clear sky and the diffuse terms of a transposition at every step.

    Parameters
    ----------
    apparent_zenith : (n_blocks, n_steps) array_like
        The sun's apparent zenith [deg]; steps at 90 or more (or NaN) are dark.
    dni_extra : (n_blocks, n_steps) array_like
        Extraterrestrial irradiance [W/m^2].
    linke_turbidity : (n_blocks, n_steps) array_like
        [-].
    altitude : (n_blocks,) array_like
        [m].
    transposition : {'none', 'isotropic', 'haydavies', 'perez'}, default 'perez'
    albedo : float, default 0.2
        Ground reflectance [-].

    Returns
    -------
    dni, ghi, dhi : numpy.ndarray
        (n_blocks, n_steps) [W/m^2], 0 in the dark.
    terms : numpy.ndarray or None
        (n_blocks, 4, n_steps) ``iso``, ``circ``, ``hor``, ``ground`` [W/m^2] (the layout the
        engine reads; :func:`foldopt.physics.irradiance.sky_diffuse_terms`' values, 0 where it
        gives NaN), or None for ``'none'``.

    Raises
    ------
    ValueError
        For a transposition that is not one of :data:`foldopt.names.TRANSPOSITIONS`.
    """
    if transposition not in TRANSPOSITION_CODES:
        raise ValueError(
            f"transposition must be one of {', '.join(names.TRANSPOSITIONS)}; got {transposition!r}"
        )
    apparent_zenith = np.ascontiguousarray(apparent_zenith, dtype=float)
    shape = apparent_zenith.shape
    inputs = [
        np.ascontiguousarray(np.broadcast_to(np.asarray(values, dtype=float), full)).view()
        for values, full in (
            (apparent_zenith, shape),
            (dni_extra, shape),
            (linke_turbidity, shape),
            (np.reshape(altitude, -1), shape[:1]),
        )
    ]
    for array in inputs:
        # Read-only whether given, broadcast or copied: numba compiles the pass again for each
        # array type it is called with, and the pass only reads them.
        array.flags.writeable = False
    dni, ghi, dhi = np.empty(shape), np.empty(shape), np.empty(shape)
    code = TRANSPOSITION_CODES[transposition]
    terms = np.empty((shape[0], 4 if code else 0, shape[1]))
    _ineichen_terms(
        *inputs,
        code,
        float(albedo),
        *perez_coefficients(),
        dni,
        ghi,
        dhi,
        terms,
    )
    return dni, ghi, dhi, (terms if code else None)
