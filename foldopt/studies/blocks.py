"""Blocks of a sky: the study's settings at each (site, date) of a set that shares one setup.

A :class:`Blocks` is what the engine evaluates as one: days at sites whose studies differ in
nothing but the site, the date, the load and the panel's orientation (:func:`setup_key`), with each
block's flat panel orientation and the study's engine options, made once
(:func:`foldopt.studies.engine_options.engine_options`); it builds its
:class:`foldopt.engine.sky.Sky` and cuts itself into chunks that bound an engine call's memory.
:mod:`foldopt.studies.designs` evaluates the designs over them.

The module may import :mod:`foldopt.engine`, :mod:`foldopt.inputs` and :mod:`foldopt.physics`.
"""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from foldopt.engine.options import EngineOptions
from foldopt.engine.sky import Sky, build_sky
from foldopt.inputs.study import Study
from foldopt.physics.spa import SunTerms
from foldopt.studies.engine_options import engine_options

#: Rows (blocks x fold angles) x loads of one engine call: bounds the memory of a chunk.
CHUNK_ROW_LOADS = 4_000_000
#: Time steps of the blocks of one chunk's sky.
CHUNK_STEPS = 1_100_000


def setup_key(study: Study) -> str:
    """What the blocks of one engine call share, as sorted JSON: everything but the site, the date and
    the load (and the panel's orientation, which follows the site).

    Parameters
    ----------
    study : Study
    """
    data = study.model_dump(mode="json", exclude={"site", "date", "p_load", "name", "description"})
    data["panel"] = {k: v for k, v in data["panel"].items() if k not in ("tilt", "azimuth")}
    return json.dumps(data, sort_keys=True)


@dataclass(frozen=True)
class Blocks:
    """Blocks that share one setup (:func:`setup_key`): the study's settings at each (site, date),
    and each block's flat panel orientation.

    Parameters
    ----------
    study : Study
        The shared settings (resolved).
    sites, dates : tuple
        Each block's site and local date.
    tilt, azimuth : numpy.ndarray
        Each block's flat panel [deg], (n_blocks,).
    options : EngineOptions
        What the engine reads of ``study`` (:func:`foldopt.studies.engine_options.engine_options`).
    member : numpy.ndarray, optional
        With a cloud ensemble (``weather.members``), each block's member (n_blocks,): a day's
        members are consecutive blocks.
    """

    study: Study
    sites: tuple
    dates: tuple
    tilt: np.ndarray
    azimuth: np.ndarray
    options: EngineOptions
    member: np.ndarray | None = None

    @property
    def members(self) -> int:
        """Members of the cloud ensemble (1 without one)."""
        weather = self.study.weather
        return weather.members if weather is not None and weather.members else 1

    @classmethod
    def of(cls, studies) -> Blocks:
        """One block per study (its site, date and panel).

        Parameters
        ----------
        studies : sequence of Study
            Of one setup; the first gives the shared settings.
        """
        for study in studies:
            study.require_files()
        return cls(
            studies[0],
            tuple(s.site for s in studies),
            tuple(s.date for s in studies),
            np.array([s.panel.tilt for s in studies]),
            np.array([s.panel.azimuth for s in studies]),
            engine_options(studies[0]),
        )

    @classmethod
    def of_dates(cls, study: Study, dates) -> Blocks:
        """The days of one study at its own site.

        Parameters
        ----------
        study : Study
        dates : sequence of datetime.date
        """
        members = (
            study.weather.members if study.weather is not None and study.weather.members else 1
        )
        dates = tuple(date for date in dates for _ in range(members))  # a day's members together
        count = len(dates)
        member = np.tile(np.arange(members), count // members) if members > 1 else None
        return cls(
            study,
            (study.site,) * count,
            dates,
            np.full(count, study.panel.tilt),
            np.full(count, study.panel.azimuth),
            engine_options(study),
            member,
        )

    @classmethod
    def join(cls, parts) -> Blocks:
        """The blocks of several :class:`Blocks` of one setup, in their order (the first's settings).

        Parameters
        ----------
        parts : sequence of Blocks
        """
        members = [part.member for part in parts]
        return cls(
            parts[0].study,
            sum((part.sites for part in parts), ()),
            sum((part.dates for part in parts), ()),
            np.concatenate([part.tilt for part in parts]),
            np.concatenate([part.azimuth for part in parts]),
            parts[0].options,
            None if any(member is None for member in members) else np.concatenate(members),
        )

    def __len__(self) -> int:
        return len(self.dates)

    def __getitem__(self, part: slice) -> Blocks:
        return Blocks(
            self.study,
            self.sites[part],
            self.dates[part],
            self.tilt[part],
            self.azimuth[part],
            self.options,
            None if self.member is None else self.member[part],
        )

    def sky(self, sun_terms: SunTerms | None = None) -> Sky:
        """The blocks' :class:`foldopt.engine.sky.Sky` (:func:`foldopt.engine.sky.build_sky`),
        sharing SPA's time-only terms with the run's other skies through ``sun_terms``."""
        return build_sky(self.options.sky, self.sites, self.dates, self.member, sun_terms=sun_terms)

    def chunks(self, n_loads: int):
        """Slices of blocks whose rows x loads and time steps stay within the chunk bounds.

        Parameters
        ----------
        n_loads : int
            Loads per row.

        Returns
        -------
        list of slice
            Consecutive, covering every block; at least one block each.
        """
        per_block = len(self.study.fold_angles.grid()) * max(n_loads, 1)
        n_steps = round(24 * 60 / self.study.step_min)
        size = max(1, min(CHUNK_ROW_LOADS // per_block, CHUNK_STEPS // n_steps))
        # A day's members stay in one chunk: they share its sun (foldopt.engine.sky.build_sky).
        size = max(self.members, size // self.members * self.members)
        return [slice(start, min(start + size, len(self))) for start in range(0, len(self), size)]
