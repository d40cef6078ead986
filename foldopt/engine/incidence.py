"""Compiled plane-of-array irradiance of a kernel row's lit steps (numba), and the incidence-angle
modifier.

:func:`incidence` is the first of the three loops of :func:`foldopt.engine.kernel.fold_rows`: both
sub-panel normals against the sun vector give the beam's incidence (or Shin et al.'s Eq. 5 in paper
mode), and the beam with the optional incidence-angle modifier (:func:`iam_factor`) and the diffuse
terms of :func:`foldopt.physics.irradiance.sky_diffuse_terms` give each sub-panel's irradiance.
It was where a map's time went while unvectorised; it is written so that LLVM vectorises it (see
:func:`incidence`; the figures are in ``docs/performance.rst``).

The module may import numpy and numba; ``tests/test_engine.py`` holds it, through the kernel, to
the NumPy reference path.
"""

from __future__ import annotations

import math

from numba import njit, uint64

IAM_NONE, IAM_ASHRAE, IAM_PHYSICAL = range(3)
IRRADIANCE_MAX = 1500.0  # [W/m^2], top of the electrical tables (foldopt.engine.electrical)


@njit(cache=True)
def iam_factor(cos_aoi, model, params):
    """Incidence-angle modifier of the beam, the arithmetic of pvlib's ``iam.ashrae`` and
    ``iam.physical`` (without coating) for one angle.

    Parameters
    ----------
    cos_aoi : float
        Cosine of the angle of incidence [-].
    model : int
        ``IAM_NONE``, ``IAM_ASHRAE`` or ``IAM_PHYSICAL``.
    params : (3,) float
        ASHRAE: ``b`` [-] (then unused); physical: ``n`` [-], ``K`` [1/m], ``L`` [m].

    Returns
    -------
    float
        Modifier [-]; 0 for light from behind, 1 for ``IAM_NONE``.

    References
    ----------
    .. [1] A. F. Souka, H. H. Safwat, "Determination of the optimum orientations for the double
       exposure flat-plate collector and its reflections", Solar Energy 10, 170-174, 1966; ASHRAE
       standard 93-77 (``1 - b (1 / cos(AOI) - 1)``).
    .. [2] W. De Soto, S. A. Klein, W. A. Beckman, "Improvement and validation of a model for
       photovoltaic array performance", Solar Energy 80(1), 78-88, 2006 (physical).
    """
    if model == IAM_NONE:
        return 1.0
    if cos_aoi <= 0.0:
        return 0.0
    if model == IAM_ASHRAE:
        return max(1.0 - params[0] * (1.0 / cos_aoi - 1.0), 0.0)
    n, k, thickness = params[0], params[1], params[2]
    sin_1 = math.sqrt(max(1.0 - cos_aoi * cos_aoi, 0.0))
    sin_2 = sin_1 / n
    cos_2 = math.sqrt(1.0 - sin_2 * sin_2)
    rho_s = ((cos_aoi - n * cos_2) / (cos_aoi + n * cos_2)) ** 2
    rho_p = ((cos_2 - n * cos_aoi) / (cos_2 + n * cos_aoi)) ** 2
    rho_0 = ((1.0 - n) / (1.0 + n)) ** 2
    absorbed = math.exp(-k * thickness / cos_2)
    return (
        ((1.0 - rho_s) * absorbed + (1.0 - rho_p) * absorbed)
        / 2.0
        / ((1.0 - rho_0) * math.exp(-k * thickness))
    )


@njit(cache=True, inline="always")
def row_arrays(sky, rows, work):
    """The arrays of the records that :func:`incidence` reads and writes, as tuples of arrays:
    ``light`` (sun, paper_sun, beam, terms of ``sky``), ``panels`` (normal, sky_view, paper of
    ``rows``) and ``lit`` (east, west, incident, diffuse_east, diffuse_west of ``work``).

    A chunk of rows takes them once, before its loop over the rows, so that each function sees
    the arrays it reads and no record (the chunk's loops count no references:
    :mod:`foldopt.engine.kernel`)."""
    return (
        (sky.sun, sky.paper_sun, sky.beam, sky.terms),
        (rows.normal, rows.sky_view, rows.paper),
        (work.east, work.west, work.incident, work.diffuse_east, work.diffuse_west),
    )


@njit(cache=True, inline="always")
def incidence_steps(r, b, start, count, light, panels, case, lit):
    """:func:`incidence`'s main loop, inlined once per case with the case's flags (``case``:
    ``paper``, ``has_terms``, ``modified``, ``root``) as constants; ``root``: each sub-panel's
    irradiance as the tables' coordinate, sqrt(E / E_max), taken in this loop (without the
    modifier: :func:`foldopt.engine.kernel._chunk_switching`). ``light``, ``panels`` and ``lit``
    are :func:`row_arrays`'."""
    paper, has_terms, modified, root = case
    sun, paper_sun, beam, terms = light
    east, west, incident, diffuse_east, diffuse_west = lit
    normal, view, row_paper = panels
    ex, ey, ez = normal[r, 0, 0], normal[r, 0, 1], normal[r, 0, 2]
    wx, wy, wz = normal[r, 1, 0], normal[r, 1, 1], normal[r, 1, 2]
    # Each sub-panel's view of the isotropic sky and of the horizon band: (1 + cos tilt) / 2 and
    # sin tilt on an open plain, less what a horizon hides (foldopt.physics.horizon).
    e_iso, e_sin_tilt = view[r, 0, 0], view[r, 0, 1]
    w_iso, w_sin_tilt = view[r, 1, 0], view[r, 1, 1]
    pe0, pe1, pe2, pe3 = (
        row_paper[r, 0, 0],
        row_paper[r, 0, 1],
        row_paper[r, 0, 2],
        row_paper[r, 0, 3],
    )
    pw0, pw1, pw2, pw3 = (
        row_paper[r, 1, 0],
        row_paper[r, 1, 1],
        row_paper[r, 1, 2],
        row_paper[r, 1, 3],
    )
    to_root = 1.0 / IRRADIANCE_MAX
    for i in range(count):
        s = start + i
        cos_east = ex * sun[b, 0, s] + ey * sun[b, 1, s] + ez * sun[b, 2, s]
        cos_west = wx * sun[b, 0, s] + wy * sun[b, 1, s] + wz * sun[b, 2, s]
        if paper:
            cz, szen, sa, ca = (
                paper_sun[b, 0, s],
                paper_sun[b, 1, s],
                paper_sun[b, 2, s],
                paper_sun[b, 3, s],
            )
            f_east = max(cz * pe0 + szen * pe1, 0.0) * max(ca * pe2 + sa * pe3, 0.0)
            f_west = max(cz * pw0 + szen * pw1, 0.0) * max(ca * pw2 + sa * pw3, 0.0)
        else:
            f_east, f_west = max(cos_east, 0.0), max(cos_west, 0.0)
        g_east, g_west = beam[b, s] * f_east, beam[b, s] * f_west
        d_east = d_west = 0.0
        if has_terms:
            iso, circ, hor, ground = terms[b, 0, s], terms[b, 1, s], terms[b, 2, s], terms[b, 3, s]
            d_east = (
                max(iso * e_iso + circ * max(cos_east, 0.0) + hor * e_sin_tilt, 0.0)
                + ground * (1.0 - ez) * 0.5
            )
            d_west = (
                max(iso * w_iso + circ * max(cos_west, 0.0) + hor * w_sin_tilt, 0.0)
                + ground * (1.0 - wz) * 0.5
            )
        incident[s] = 0.5 * (g_east + d_east + g_west + d_west)
        if modified:
            east[s], west[s], diffuse_east[s], diffuse_west[s] = g_east, g_west, d_east, d_west
        elif root:
            east[s] = math.sqrt(min(max(g_east + d_east, 0.0), IRRADIANCE_MAX) * to_root)
            west[s] = math.sqrt(min(max(g_west + d_west, 0.0), IRRADIANCE_MAX) * to_root)
        else:
            east[s], west[s] = g_east + d_east, g_west + d_west


@njit(cache=True, inline="always")
def incidence(r, b, first, n, arrays, how, tables):
    """Both sub-panels' irradiance at steps ``first .. first + n - 1`` of row ``r`` (over block
    ``b``) into ``east`` and ``west`` (as sqrt(E / E_max) with ``tables``), and their mean incident
    irradiance before the incidence-angle modifier into ``incident`` [W/m^2]: ``arrays`` is
    :func:`row_arrays`' (``light``, ``panels``, ``lit``) of a
    :class:`foldopt.engine.records.SkyArrays`, its rows and a chunk's
    :class:`foldopt.engine.records.Scratch`, ``how`` the sky's ``paper``, ``iam_model`` and
    ``iam_params``.

    The steps are indexed as unsigned integers, so that no index can wrap around, and the main
    loop (:func:`incidence_steps`) is inlined once per case, its flags constants: LLVM then
    vectorises each. The incidence-angle modifier, a call per step, has a loop of its own (the beam
    waits for it in ``east`` and ``west``, the diffuse light in ``diffuse_east`` and
    ``diffuse_west``), as has the tables' coordinate."""
    light, panels, lit = arrays
    paper, iam_model, iam_params = how
    start, count = uint64(first), uint64(n)
    has_terms = light[3].shape[1] == 4
    modified = iam_model != IAM_NONE
    # Exact incidence without the modifier, with or without diffuse terms, as constants (every
    # study of a year or a map); paper mode and the modifier read their flags at run time.
    if not paper and not modified and has_terms:
        incidence_steps(r, b, start, count, light, panels, (False, True, False, False), lit)
    elif not paper and not modified:
        incidence_steps(r, b, start, count, light, panels, (False, False, False, False), lit)
    else:
        case = (paper, has_terms, modified, False)
        incidence_steps(r, b, start, count, light, panels, case, lit)
    east, west, _, diffuse_east, diffuse_west = lit
    if modified:
        sun, normal = light[0], panels[0]
        ex, ey, ez = normal[r, 0, 0], normal[r, 0, 1], normal[r, 0, 2]
        wx, wy, wz = normal[r, 1, 0], normal[r, 1, 1], normal[r, 1, 2]
        for i in range(count):
            s = start + i
            cos_east = ex * sun[b, 0, s] + ey * sun[b, 1, s] + ez * sun[b, 2, s]
            cos_west = wx * sun[b, 0, s] + wy * sun[b, 1, s] + wz * sun[b, 2, s]
            east[s] = east[s] * iam_factor(cos_east, iam_model, iam_params) + diffuse_east[s]
            west[s] = west[s] * iam_factor(cos_west, iam_model, iam_params) + diffuse_west[s]
    if tables:
        to_root = 1.0 / IRRADIANCE_MAX
        for i in range(count):
            s = start + i
            east[s] = math.sqrt(min(max(east[s], 0.0), IRRADIANCE_MAX) * to_root)
            west[s] = math.sqrt(min(max(west[s], 0.0), IRRADIANCE_MAX) * to_root)


@njit(cache=True, inline="always")
def steps_sum(values, first, n):
    """The sum of ``values[first .. first + n - 1]`` in four interleaved partial sums, so that it
    does not wait on each addition (the order of the additions is fixed, so are the bits)."""
    start, count = uint64(first), uint64(n)
    whole = count - count % uint64(4)
    a = b = c = d = 0.0
    for i in range(uint64(0), whole, uint64(4)):
        s = start + i
        a += values[s]
        b += values[s + uint64(1)]
        c += values[s + uint64(2)]
        d += values[s + uint64(3)]
    for i in range(whole, count):
        a += values[start + i]
    return (a + b) + (c + d)


@njit(cache=True)
def turning_poa(normal, sun, beam, terms, span, poa):
    """Plane-of-array irradiance [W/m^2] of a surface whose normal turns step by step (a tracker's)
    over every block, into ``poa`` (n_blocks, n_steps), 0 outside each block's span.

    The arithmetic of :func:`foldopt.physics.irradiance.plane_of_array` for the exact incidence on
    an open plain without an incidence-angle modifier, in its order of operations (so the same
    bits), walked over the span alone: outside it there is no light, and the NumPy expression gives 0
    there too. ``normal`` is (n_blocks, 3, n_steps), each component along the steps as the sun's;
    ``sun``, ``beam``, ``terms`` and ``span`` are :meth:`foldopt.engine.sky.Sky.kernel_layout`'s."""
    has_terms = terms.shape[1] == 4
    for b in range(normal.shape[0]):
        poa[b, :] = 0.0
        for s in range(span[b, 0], span[b, 1] + 1):
            nx, ny, nz = normal[b, 0, s], normal[b, 1, s], normal[b, 2, s]
            cos_aoi = nx * sun[b, 0, s] + ny * sun[b, 1, s] + nz * sun[b, 2, s]
            lit = max(cos_aoi, 0.0)
            value = beam[b, s] * lit
            if has_terms:
                sky = max(
                    terms[b, 0, s] * ((1.0 + nz) * 0.5)
                    + terms[b, 1, s] * lit
                    + terms[b, 2, s] * math.sqrt(max(1.0 - nz * nz, 0.0)),
                    0.0,
                )
                value = value + sky + terms[b, 3, s] * (1.0 - nz) * 0.5
            poa[b, s] = value
