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


#: Options of ``foldopt sweep`` and ``optimize`` that set no study field, by parameter.
_OWN_OPTIONS = {"config", "settings", "out", "overwrite", "quiet", "output_format", "engine", "table", "vary",
                "fold_range", "tilt_range", "azimuth_range", "tolerance", "offline"}


@pytest.mark.parametrize("path", [["sweep", axis] for axis in ("angle", "latitude", "day", "load")] + [["optimize"]],
                         ids=" ".join)
def test_the_options_that_set_fields_are_one_table(path):
    """Every option of the command that sets a study field is an entry of names.FIELD_OPTIONS,
    spelt as the command declares it, and every entry is such an option: the options become field
    changes, and a message's field becomes the option, through that one table."""
    import typer.main

    command = typer.main.get_command(app)
    for name in path:
        command = command.commands[name]
    declared = {param.name: [*param.opts, *param.secondary_opts] for param in command.params}
    for entry in names.FIELD_OPTIONS:
        assert sorted(declared[entry.parameter]) == sorted([entry.option, *entry.aliases]), entry
    assert set(declared) - _OWN_OPTIONS == set(names.FIELD_OF_PARAMETER)


def test_a_flag_sets_its_field_to_the_table_value():
    from foldopt.studies.request import make_request

    # what makes each flag's field used (an unused setting is refused)
    context = {"no_bypass": ["connection=series"], "exact_electrical": ["pv_model=single-diode"]}
    for entry in names.FIELD_OPTIONS:
        if entry.flag is not None:
            request = make_request("sweep angle", options={entry.parameter: True},
                                   settings=context.get(entry.parameter, []))
            study = request.plan.base
            section, _, name = entry.field.rpartition(".")
            assert getattr(getattr(study, section) if section else study, name) == entry.flag, entry
    assert names.option_labels()["fold_angles.start"] == "--angle-step"
    assert names.option_labels({"p_load_scale"})["p_load"] == "--p-load-scale"
