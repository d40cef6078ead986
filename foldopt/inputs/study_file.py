"""Reading what a user hands in: YAML study files, the files a study names, within size limits.

A study file is YAML read by :class:`StudyLoader` (PyYAML's safe loader without aliases, keys
given twice, base-60 numbers or timestamps), each key's line kept for the messages
(:func:`parse_study_text`, :func:`read_study`). Every input file goes through :func:`foldopt.inputs.reading.read_input`
(UTF-8, a size limit, no device or FIFO). A study's own files, its weather file and its load
profile's CSV, are read by :func:`resolve_files` before the study is validated, so that the models
of :mod:`foldopt.inputs.study` open no files; :func:`with_files` does the same for a study built in
Python.
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import yaml

from foldopt.errors import ConfigError
from foldopt.inputs.fields import FilesRead
from foldopt.inputs.horizon import read_horizon
from foldopt.inputs.load_profile import profile_steps
from foldopt.inputs.reading import MAX_CSV_BYTES, MAX_STUDY_BYTES, read_input
from foldopt.inputs.study import Study, make_study
from foldopt.inputs.weather_files import weather_read, with_fetched_horizon, with_fetched_weather

DEFAULT_STUDY = "shin2015"


class StudyLoader(yaml.SafeLoader):
    """YAML for studies: PyYAML's safe loader, less what a study never needs and an attacker or a
    slip would use. Aliases (``*name``) are refused, so no "billion laughs" expansion; a key given
    twice in one mapping is an error rather than silently the last; dates stay text, so that the
    schema validates them (``2025-02-30`` is a field error, not a crash in the parser).

    Parameters
    ----------
    stream : str
        The YAML text.
    """

    yaml_implicit_resolvers = {
        first: [(tag, regexp) for tag, regexp in resolvers if tag != "tag:yaml.org,2002:timestamp"]
        for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
    }

    def compose_node(self, parent, index):
        """PyYAML's node composition, an alias refused.

        Parameters
        ----------
        parent, index
            As :meth:`yaml.composer.Composer.compose_node`.

        Returns
        -------
        yaml.Node

        Raises
        ------
        yaml.composer.ComposerError
            At an alias (``*name``).
        """
        if self.check_event(yaml.AliasEvent):
            raise yaml.composer.ComposerError(
                None,
                None,
                "aliases (*name) are not accepted in a study; write the value out",
                self.peek_event().start_mark,
            )
        return super().compose_node(parent, index)

    def construct_mapping(self, node, deep=False):
        """PyYAML's mapping, a key given twice refused.

        Parameters
        ----------
        node : yaml.MappingNode
        deep : bool

        Returns
        -------
        dict

        Raises
        ------
        yaml.constructor.ConstructorError
            Naming the key and the line of its first appearance.
        """
        first: dict = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                if key in first:
                    raise yaml.constructor.ConstructorError(
                        None,
                        None,
                        f"key {key!r} appears twice (first at line {first[key]})",
                        key_node.start_mark,
                    )
                first[key] = key_node.start_mark.line + 1
            except TypeError:  # an unhashable key: the base class says so
                break
        return super().construct_mapping(node, deep)

    def construct_yaml_int(self, node):
        """An integer, unless YAML 1.1 would read it in base 60 (:meth:`_not_sexagesimal`).

        Parameters
        ----------
        node : yaml.ScalarNode

        Returns
        -------
        int
        """
        self._not_sexagesimal(node, "construct_yaml_int")
        return super().construct_yaml_int(node)

    def construct_yaml_float(self, node):
        """A float, unless YAML 1.1 would read it in base 60 (:meth:`_not_sexagesimal`).

        Parameters
        ----------
        node : yaml.ScalarNode

        Returns
        -------
        float
        """
        self._not_sexagesimal(node, "construct_yaml_float")
        return super().construct_yaml_float(node)

    def _not_sexagesimal(self, node, constructor: str):
        """YAML 1.1 reads ``19:00`` as the base-60 number 1140 and ``1:9:4`` as 4144: a clock time
        or a range written without quotes would be a wrong number, silently."""
        text = self.construct_scalar(node)
        if ":" in text:
            value = getattr(super(), constructor)(node)
            raise yaml.constructor.ConstructorError(
                None,
                None,
                f"{text} is read by YAML as the number {value:g} (base 60); write '{text}' in quotes",
                node.start_mark,
            )


StudyLoader.add_constructor("tag:yaml.org,2002:int", StudyLoader.construct_yaml_int)
StudyLoader.add_constructor("tag:yaml.org,2002:float", StudyLoader.construct_yaml_float)


def _yaml_lines(node, path=(), out=None) -> dict:
    """Map every key path of a composed YAML node to its 1-based line."""
    out = {} if out is None else out
    if isinstance(node, yaml.MappingNode):
        for key, value in node.value:
            child = path + (str(key.value),)
            out[child] = key.start_mark.line + 1
            _yaml_lines(value, child, out)
    elif isinstance(node, yaml.SequenceNode):
        for index, item in enumerate(node.value):
            out[path + (str(index),)] = item.start_mark.line + 1
            _yaml_lines(item, path + (str(index),), out)
    return out


def read_study(path: Path | str) -> tuple:
    """The data of a YAML study file and the line of each of its keys.

    Parameters
    ----------
    path : str or pathlib.Path

    Returns
    -------
    data : object
        The study's fields (a mapping, for a study); a relative weather path is made relative to
        the file.
    lines : dict
        Each key path (a tuple of str) to its 1-based line.

    Raises
    ------
    foldopt.ConfigError
        For a file that :func:`read_input` refuses (larger than :data:`MAX_STUDY_BYTES`...) or
        that is not a plain YAML study (:class:`StudyLoader`).
    """
    path = Path(path)
    text = read_input(path, "config", MAX_STUDY_BYTES, "MAX_STUDY_BYTES", "study file")
    data, lines = parse_study_text(text, str(path))
    if isinstance(data, dict):
        data = _resolve_horizon_path(_resolve_weather_path(data, path.parent), path.parent)
    return data, lines


def parse_study_text(text: str, source: str = "config") -> tuple:
    """The data of a study's YAML text (or of one ``--set`` value).

    Parameters
    ----------
    text : str
    source : str
        What messages name the text by (a file's path).

    Returns
    -------
    data : object
        The YAML document, None for an empty one.
    lines : dict
        Each key path (a tuple of str) to its 1-based line.

    Raises
    ------
    foldopt.ConfigError
        ``config: <source> at line <n>: <problem>`` for anything :class:`StudyLoader` refuses.
    """
    loader = StudyLoader(text)
    try:
        node = loader.get_single_node()
        data = loader.construct_document(node) if node is not None else None
    except yaml.YAMLError as error:
        where = getattr(error, "problem_mark", None)
        line = f" at line {where.line + 1}" if where is not None else ""
        problem = getattr(error, "problem", None) or "malformed YAML"
        raise ConfigError([f"config: {source}{line}: {problem}"]) from None
    except RecursionError:
        raise ConfigError([f"config: {source}: nested too deeply"]) from None
    finally:
        loader.dispose()
    return data, (_yaml_lines(node) if node is not None else {})


def _resolve_weather_path(data: dict, folder: Path) -> dict:
    """A study file's relative weather path is relative to the file, not to the working folder."""
    weather = data.get("weather")
    spec = weather.get("path") if isinstance(weather, dict) else weather
    if isinstance(spec, str) and not Path(spec).is_absolute() and (folder / spec).is_file():
        resolved = str(folder / spec)
        data = {
            **data,
            "weather": {**weather, "path": resolved} if isinstance(weather, dict) else resolved,
        }
    return data


def _resolve_horizon_path(data: dict, folder: Path) -> dict:
    """A study file's relative horizon file is relative to the file, as its weather file is."""
    site = data.get("site")
    horizon = site.get("horizon") if isinstance(site, dict) else None
    spec = horizon.get("file") if isinstance(horizon, dict) else horizon
    if isinstance(spec, str) and not Path(spec).is_absolute() and (folder / spec).is_file():
        resolved = str(folder / spec)
        data = {
            **data,
            "site": {
                **site,
                "horizon": {**horizon, "file": resolved} if isinstance(horizon, dict) else resolved,
            },
        }
    return data


def default_study_path(name: str = DEFAULT_STUDY) -> Path:
    """The path of a study shipped with foldopt.

    Parameters
    ----------
    name : str
        The study's name (a file ``<name>.yaml``); default the embedded study.

    Returns
    -------
    pathlib.Path
        In ``configs/`` of the wheel, or of the checkout.
    """
    # foldopt/, this module being foldopt/inputs/<name>.py
    package = Path(__file__).resolve().parents[1]
    packaged = package / "configs" / f"{name}.yaml"
    if packaged.exists():
        return packaged
    return package.parent / "configs" / f"{name}.yaml"


def read_profile(path: str | Path) -> dict:
    """A day's load profile from a CSV file.

    Parameters
    ----------
    path : str or pathlib.Path
        A file with a header ``time,watts`` and one row per clock time (``HH:MM``, watts), UTF-8
        with or without a byte-order mark, at most :data:`MAX_CSV_BYTES`.

    Returns
    -------
    dict
        Clock times ``HH:MM`` to loads [W] in time order (:func:`foldopt.inputs.load_profile.profile_steps`).

    Raises
    ------
    foldopt.ConfigError
        One line naming the file (and the line): unreadable, a row that is no ``time,watts``, a
        time given twice, or a value :func:`~foldopt.inputs.load_profile.profile_steps` refuses.
    """
    path = Path(path)
    text = read_input(path, "load_profile.file", MAX_CSV_BYTES, "MAX_CSV_BYTES", "load profile")
    try:
        reader = csv.DictReader(io.StringIO(text, newline=""))
        rows = [(reader.line_num, row) for row in reader]
    except csv.Error as error:
        raise ConfigError([f"load_profile.file: cannot read {path}: {error}"]) from None
    steps, lines = {}, {}
    for line, row in rows:
        try:
            time, watts = row["time"].strip(), float(row["watts"])
        except (KeyError, TypeError, ValueError, AttributeError):
            raise ConfigError(
                [f"load_profile.file {path}, line {line}: expected time,watts (HH:MM, a number)"]
            ) from None
        if time in steps:  # the second load would replace the first unseen
            raise ConfigError(
                [
                    f"load_profile.file {path}, line {line}: time {time} is also on line {lines[time]}; "
                    "give each time once"
                ]
            )
        steps[time], lines[time] = watts, line
    try:
        return profile_steps(steps)
    except ValueError as error:
        raise ConfigError([f"load_profile.file {path}: {error}"]) from None


def resolve_files(data) -> FilesRead:
    """Read the files a study's data names, for its validation (pydantic's context).

    Parameters
    ----------
    data : dict
        A study's fields, as a YAML study holds them: ``weather`` (a path, or a mapping with
        ``path`` and ``format``) and ``load_profile.file`` are read.

    Returns
    -------
    FilesRead
        The weather file's site (:func:`foldopt.inputs.weather.reader.weather_site`) and the
        profile's day (:func:`read_profile`), or why each cannot be read; the study's validation
        reports that where the file is needed, in the words it always used (the field, the file,
        the line).
    """
    if not isinstance(data, dict):
        return FilesRead()
    return FilesRead(
        **weather_read(data.get("weather"), data.get("site")),
        **_profile_read(data.get("load_profile")),
        **_horizon_read(data.get("site")),
    )


def _profile_read(profile) -> dict:
    path = profile.get("file") if isinstance(profile, dict) else None
    if not isinstance(path, str):
        return {}
    try:
        return {"profile_daily": read_profile(path)}
    except ConfigError as error:
        return {"profile_problem": str(error)}


def _horizon_read(site) -> dict:
    horizon = site.get("horizon") if isinstance(site, dict) else None
    path = horizon.get("file") if isinstance(horizon, dict) else horizon
    if not isinstance(path, str):
        return {}
    try:
        azimuth, elevation = read_horizon(path)
    except ConfigError as error:
        return {"horizon_problem": str(error).removeprefix("site.horizon: ")}
    return {
        "horizon_points": [[float(a), float(e)] for a, e in zip(azimuth, elevation, strict=True)]
    }


def with_files(study: Study) -> Study:
    """A study validated with the files it names read: what the API runs.

    A study built in Python (``foldopt.Study(weather=...)``) or made by
    :meth:`~foldopt.inputs.study.Study.variant` is validated without its files
    (:class:`~foldopt.inputs.sections.FilesRead`): its weather file's site is unread and unchecked
    against the study's, its profile file's day unread.

    Parameters
    ----------
    study : Study

    Returns
    -------
    Study
        ``study`` itself where it names no file; otherwise validated again, its files read.

    Raises
    ------
    foldopt.ConfigError
        For a file that cannot be used, or a site too far from the weather file's.
    """
    horizon = study.site.horizon if study.site is not None else None
    if (
        study.weather is None
        and (study.load_profile is None or study.load_profile.file is None)
        and (horizon is None or horizon.read)
    ):
        return study
    data = with_fetched_horizon(with_fetched_weather(study.data()))
    return make_study(data, resolve_files(data))
