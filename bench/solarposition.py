"""What splitting SPA buys: foldopt's exact solar position against pvlib's public API.

    python bench/solarposition.py                    # 1, 100 and 10 000 sites, printed
    python bench/solarposition.py --sites 1 100 --days 30 --step 5

Workload: a year (``--days``) of interval-centred steps (``--step`` minutes, 1 by default) in
UTC at each of N random sites (latitude 60 S to 70 N, any longitude, altitude 0 to 3000 m); for
each site the apparent zenith, the azimuth and the equation of time at every step, which is what
foldopt's exact mode needs. Timed, as seconds for the whole workload:

- ``foldopt split``: :func:`foldopt.physics.solarposition.solar_position_grid`, SPA's time-only
  (geocentric) part once per UTC hour and its direction once per step for all sites, the
  per-site (topocentric) part at every step as a rotation of it, and the refraction; sites in
  chunks of ``--chunk`` (as the map runs them), so memory stays bounded;
- ``pvlib get_solarposition``: ``pvlib.solarposition.get_solarposition`` (``nrel_numpy``, i.e.
  ``spa_python``) at every step, one call per site;
- ``pvlib, 10-min + interp``: the same public call every 10 minutes only, with foldopt's
  interpolation of the sun vector and refraction at every step (what the public API allows
  without the split);
- ``spa_python numba``: ``spa_python(how='numba', numthreads=2)`` at every step, in a child
  process (it reloads ``pvlib.spa`` compiled, which breaks array calls into it for the rest of
  the process), compilation excluded.

The split is measured in full up to ``--split-sample`` sites and scaled per site beyond; the pvlib
paths cost one call per site, so they are measured on ``--pvlib-sample`` sites and scaled. Scaled
figures are marked ``*``. Last, the split's largest difference from ``get_solarposition`` on the
sites pvlib ran: the angle between the two sun directions and the apparent zenith, over steps with
the sun above -1 deg, except within 0.01 deg of -0.8334 deg geometric elevation, where SPA
switches its refraction off (a jump of up to 0.6 deg that any difference in the geometric
elevation can move across a step, with the sun's disc below the horizon); how many steps that
leaves out is printed too.
"""

from __future__ import annotations

import argparse
import datetime as dt
import json
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

STRIDE_MIN = 10.0  # [min] the public call's spacing in the subsampled comparison


def _sites(n: int, seed: int = 7) -> np.ndarray:
    """(n, 3): latitude [deg], longitude [deg], altitude [m]."""
    rng = np.random.default_rng(seed)
    return np.column_stack([rng.uniform(-60, 70, n), rng.uniform(-180, 180, n), rng.uniform(0, 3000, n)])


def _dates(days: int):
    return [dt.date(2025, 1, 1) + dt.timedelta(days=d) for d in range(days)]


def _split(sites: np.ndarray, dates, step_min: float, chunk: int) -> float:
    """Seconds for foldopt's split over every site x date, ``chunk`` sites per call."""
    from foldopt.physics.solarposition import clock_grid, solar_position_grid

    start = time.perf_counter()
    grid = clock_grid(dates, "UTC", step_min)
    for first in range(0, len(sites), chunk):
        part = sites[first:first + chunk]
        blocks = np.repeat(part, len(dates), axis=0)[:, :, None]  # site-major, one block per date
        many = type(grid).stack([grid] * len(part))
        solar_position_grid(many, blocks[:, 0], blocks[:, 1], blocks[:, 2], "exact")
    return time.perf_counter() - start


def _site_times(dates, step_min: float) -> pd.DatetimeIndex:
    from foldopt.physics.solarposition import clock_grid

    grid = clock_grid(dates, "UTC", step_min)
    return pd.DatetimeIndex(grid.utc_ns.ravel().astype("datetime64[ns]"), tz="UTC")


def _pvlib_full(sites, times) -> tuple[float, list]:
    import pvlib

    start, out = time.perf_counter(), []
    for latitude, longitude, altitude in sites:
        out.append(pvlib.solarposition.get_solarposition(times, latitude, longitude, altitude))
    return time.perf_counter() - start, out


def _pvlib_subsampled(sites, times, step_min: float) -> float:
    """The public call every 10 minutes, the sun vector interpolated, refraction at every step."""
    import pvlib

    stride = max(int(STRIDE_MIN // step_min), 1)
    position = np.arange(len(times))
    picked = np.unique(np.r_[np.arange(0, len(times), stride), len(times) - 1])
    start = time.perf_counter()
    for latitude, longitude, altitude in sites:
        sun = pvlib.solarposition.get_solarposition(times[picked], latitude, longitude, altitude)
        zenith, azimuth = np.radians(sun["zenith"].to_numpy()), np.radians(sun["azimuth"].to_numpy())
        east, north, up = (np.interp(position, picked, c) for c in
                           (np.sin(zenith) * np.sin(azimuth), np.sin(zenith) * np.cos(azimuth), np.cos(zenith)))
        np.interp(position, picked, sun["equation_of_time"].to_numpy())
        elevation = np.degrees(np.arctan2(up, np.hypot(east, north)))
        pvlib.spa.atmospheric_refraction_correction(pvlib.atmosphere.alt2pres(altitude) / 100.0, 12.0, elevation,
                                                    0.5667)
        np.degrees(np.arctan2(east, north)) % 360.0
    return time.perf_counter() - start


def _numba_child(sites, days: int, step_min: float) -> float:
    """Seconds for spa_python(how='numba') at every step of ``sites``, measured in a child process."""
    code = f"""
import json, sys, time, warnings
sys.path.insert(0, {str(ROOT)!r})
import numpy as np, pvlib
sys.path.insert(0, {str(Path(__file__).parent)!r})
from solarposition import _dates, _site_times
times = _site_times(_dates({days}), {step_min})
sites = np.array({sites.tolist()!r})
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    pvlib.solarposition.spa_python(times[:100], 0.0, 0.0, how="numba", numthreads=2)  # compiled here
    start = time.perf_counter()
    for lat, lon, alt in sites:
        pvlib.solarposition.spa_python(times, lat, lon, alt, pressure=pvlib.atmosphere.alt2pres(alt),
                                       how="numba", numthreads=2)
print(json.dumps(time.perf_counter() - start))
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def _agreement(sites, dates, step_min: float, reference: list) -> tuple[float, float, int]:
    """Largest sun-direction angle and apparent-zenith difference [deg], split against pvlib, and
    the number of steps left out at SPA's refraction switch."""
    from foldopt.physics.geometry import normal_vector
    from foldopt.physics.solarposition import clock_grid, solar_position_grid
    from foldopt.physics.spa_site import SPA_ATMOS_REFRACT

    grid = clock_grid(dates, "UTC", step_min)
    switch = -(0.26667 + SPA_ATMOS_REFRACT)  # [deg] SPA Eq. 42's limit: the sun's radius below the horizon
    angle = zenith = 0.0
    left_out = 0
    for (latitude, longitude, altitude), spa in zip(sites, reference, strict=True):
        sun = solar_position_grid(grid, latitude, longitude, altitude, "exact")
        elevation = spa["elevation"].to_numpy()
        at_switch = np.abs(elevation - switch) < 0.01
        up = (spa["apparent_elevation"].to_numpy() > -1.0) & ~at_switch
        left_out += int(at_switch.sum())
        ours = normal_vector(sun["solar_zenith"].ravel(), sun["solar_azimuth"].ravel())[up]
        theirs = normal_vector(spa["apparent_zenith"].to_numpy(), spa["azimuth"].to_numpy())[up]
        cross = np.linalg.norm(np.cross(ours, theirs), axis=1)
        angle = max(angle, float(np.degrees(np.arctan2(cross, np.sum(ours * theirs, axis=1))).max()))
        difference = sun["solar_zenith"].ravel()[up] - spa["apparent_zenith"].to_numpy()[up]
        zenith = max(zenith, float(np.abs(difference).max()))
    return angle, zenith, left_out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sites", type=int, nargs="+", default=[1, 100, 10_000])
    parser.add_argument("--days", type=int, default=365)
    parser.add_argument("--step", type=float, default=1.0, help="step [min]")
    parser.add_argument("--chunk", type=int, default=20, help="sites per call of the split")
    parser.add_argument("--split-sample", type=int, default=200, help="sites the split runs in full at most")
    parser.add_argument("--pvlib-sample", type=int, default=2, help="sites each pvlib path runs")
    parser.add_argument("--no-numba", action="store_true", help="skip spa_python(how='numba')")
    args = parser.parse_args()

    import pvlib

    dates = _dates(args.days)
    steps = len(dates) * round(1440 / args.step)
    sample = _sites(max(args.pvlib_sample, 1))
    times = _site_times(dates, args.step)
    _split(sample[:1], dates[:2], args.step, args.chunk)  # imports and first-call costs outside the clock
    full_s, reference = _pvlib_full(sample, times)
    per_site = {"pvlib get_solarposition": full_s / len(sample),
                "pvlib, 10-min + interp": _pvlib_subsampled(sample, times, args.step) / len(sample)}
    if not args.no_numba:
        per_site["spa_python numba"] = _numba_child(sample, args.days, args.step) / len(sample)
    split = {}
    for n in sorted(set(args.sites)):
        measured = min(n, args.split_sample)
        split[n] = (_split(_sites(measured, seed=11), dates, args.step, args.chunk) * n / measured, measured < n)

    print(f"solar position, {args.days} days x {round(1440 / args.step)} steps ({steps} per site), "
          f"pvlib {pvlib.__version__}, numpy {np.__version__}, {platform.processor() or platform.machine()}")
    print(f"{'sites':>7} {'foldopt split':>15}" + "".join(f" {name:>25}" for name in per_site)
          + f" {'speed-up vs get_solarposition':>31}")
    for n, (seconds, scaled) in split.items():
        mark = "*" if scaled else " "
        row = f"{n:>7} {seconds:>13.2f} s{mark}"
        for name, cost in per_site.items():
            row += f" {cost * n:>22.2f} s{'*' if n > len(sample) else ' '} "
        row += f" {per_site['pvlib get_solarposition'] * n / seconds:>29.1f}x"
        print(row)
    print("  * scaled per site from a smaller measured run (see the module docstring)")
    angle, zenith, left_out = _agreement(sample, dates, args.step, reference)
    print(f"split vs get_solarposition on {len(sample)} sites, sun above -1 deg: sun direction within {angle:.1e} deg, "
          f"apparent zenith within {zenith:.1e} deg ({left_out} of {steps * len(sample)} steps at SPA's "
          "refraction switch left out)")


if __name__ == "__main__":
    main()
