"""``run.json``: what a results folder was made from, so that it can be made again. The resolved
study, its mode, the command line, the versions (:func:`foldopt.files.versions`), a digest of the
inputs and what each kind of result adds (its engine, its answer's headline numbers). An address
it holds (a mirror's ``weather.url``, the request of fetched weather) is
:func:`foldopt.errors.redacted`: ``run.json`` and the report never keep a password or a key."""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path

from foldopt.errors import redacted
from foldopt.files import versions
from foldopt.inputs.study import Study


def run_metadata(study: Study, command: list[str] | None = None, **extra) -> dict:
    """The content of ``run.json``.

    Parameters
    ----------
    study : foldopt.Study
        The study that ran, resolved (its defaults filled in).
    command : list of str, optional
        The command line to record; default ``sys.argv``.
    **extra
        Further entries, after the standard ones, in their order (JSON-serialisable, or floats).

    Returns
    -------
    dict
        ``study`` (the study as JSON), ``mode``, ``command``, ``versions``, for weather fetched
        from a source ``weather_source`` (:func:`weather_source`), for a horizon fetched from one
        ``horizon_source`` (:func:`horizon_source`), and ``extra``; every address in it
        :func:`foldopt.errors.redacted`.
    """
    fetched = weather_source(study)
    horizon = horizon_source(study)
    return redacted(
        {
            "study": study.model_dump(mode="json"),
            "mode": study.mode,
            "command": command if command is not None else sys.argv,
            "versions": versions(),
            **({"weather_source": fetched} if fetched is not None else {}),
            **({"horizon_source": horizon} if horizon is not None else {}),
            **extra,
        }
    )


def weather_source(study: Study) -> dict | None:
    """Where a study's fetched weather came from: the source, the request, when it was
    retrieved and the SHA-256 of the cached answer the study read
    (:class:`foldopt.inputs.weather.sources.WeatherProvenance`); None for a weather file.

    Parameters
    ----------
    study : foldopt.Study

    Returns
    -------
    dict or None
    """
    weather = study.weather
    if weather is None or weather.source is None or weather.path is None:
        return None
    from foldopt.inputs.weather.sources import cached

    found = cached(weather.path)
    return found.to_dict() if found is not None else None


def horizon_source(study: Study) -> dict | None:
    """Where a study's fetched horizon came from (``--horizon pvgis``), as :func:`weather_source`
    says of its weather; None for a horizon given as points or as the user's file.

    Parameters
    ----------
    study : foldopt.Study

    Returns
    -------
    dict or None
    """
    horizon = study.site.horizon if study.site is not None else None
    if horizon is None or horizon.file is None:
        return None
    from foldopt.inputs.weather.sources import HORIZON_SOURCES, cached

    found = cached(horizon.file)
    fetched = {source.name for source in HORIZON_SOURCES.values()}
    return found.to_dict() if found is not None and found.source in fetched else None


def input_hash(data) -> str:
    """SHA-256 of the canonical JSON of a study's inputs (keys sorted, no spaces), their addresses
    :func:`foldopt.errors.redacted` (a digest of a password is no place for it).

    Parameters
    ----------
    data : dict
        The inputs, as JSON-like data (values that are not JSON are written as their ``str``).

    Returns
    -------
    str
        The digest, 64 hexadecimal characters.
    """
    canonical = json.dumps(redacted(data), sort_keys=True, default=str, separators=(",", ":"))
    return hashlib.sha256(canonical.encode()).hexdigest()


def write_run_json(folder: Path, metadata: dict) -> Path:
    """Write ``folder/run.json``: ``metadata`` as indented JSON (ASCII; numpy numbers as floats).

    Parameters
    ----------
    folder : pathlib.Path
        The results folder being written (a staged folder, :func:`foldopt.files.staged_folder`).
    metadata : dict
        Usually :func:`run_metadata`'s.

    Returns
    -------
    pathlib.Path
        The file written.
    """
    path = Path(folder) / "run.json"
    path.write_text(json.dumps(metadata, indent=2, sort_keys=False, default=float) + "\n")
    return path
