"""Each kind with several members is one registry (foldopt.names) that validation, "did you mean",
the command line's help and the docs all read: a name the registry gains is accepted everywhere,
and a bad name is refused with the registry's own list."""

from __future__ import annotations

import pickle
import re

import pytest
from typer.testing import CliRunner

import foldopt
from foldopt import names
from foldopt.cli.app import app

#: A study field and the registry whose names it takes.
FIELDS = [("mode", names.MODES), ("geometry", names.GEOMETRIES), ("sky", names.SKIES),
          ("transposition", names.TRANSPOSITIONS), ("iam", names.IAMS), ("pv_model", names.PV_MODELS),
          ("connection", names.CONNECTIONS), ("temperature_model", names.TEMPERATURE_MODELS),
          ("climate", names.HOTTEL_CLIMATES), ("tracker.model", names.TRACKERS), ("tracker.drive", names.DRIVES)]


def _variant(field: str, value):
    section, _, leaf = field.rpartition(".")
    return foldopt.default_study().variant(**({section: {leaf: value}} if section else {field: value}))


@pytest.mark.parametrize("registry", names.REGISTRIES, ids=lambda r: r.kind)
def test_every_member_is_named_once_and_described(registry):
    assert len(set(registry)) == len(registry)
    assert all(re.fullmatch(r"[a-z0-9]+(-[a-z0-9]+)*", name) for name in registry)
    assert all(len(registry.describe(name)) > 10 for name in registry)
    assert pickle.loads(pickle.dumps(registry)) == registry  # as Dask ships it
    assert pickle.loads(pickle.dumps(registry)).descriptions == registry.descriptions


@pytest.mark.parametrize(("field", "registry"), FIELDS, ids=[f for f, _ in FIELDS])
def test_validation_refuses_with_the_registry_list(field, registry):
    with pytest.raises(foldopt.ConfigError) as error:
        _variant(field, "no-such-model")
    assert f"must be one of {', '.join(registry)}" in str(error.value)


@pytest.mark.parametrize(("field", "registry"), FIELDS, ids=[f for f, _ in FIELDS])
def test_did_you_mean_comes_from_the_registry(field, registry):
    name = max(registry, key=len)
    with pytest.raises(foldopt.ConfigError, match=f"did you mean '{re.escape(name)}'"):
        _variant(field, name[:-1] + "x")


def test_help_lists_the_registries():
    runner = CliRunner()
    text = re.sub(r"[\s│]+", " ", runner.invoke(app, ["sweep", "angle", "--help"], terminal_width=400).output)
    for registry in (names.PV_MODELS, names.CONNECTIONS, names.TRACKERS):
        assert registry.choices() in text, registry.kind
