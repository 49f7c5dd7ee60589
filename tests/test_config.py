"""Layered configuration: merging, overrides, the private layer."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from tafel.core.framework.config import (
    ConfigError,
    apply_overrides,
    context_section,
    dump_toml,
    load_config,
    merge,
    parse_override,
    store_private,
)


def write(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)


@pytest.fixture
def config_dir(tmp_path: Path) -> Path:
    write(tmp_path / "general.toml", '[runtime]\ncognition_hz = 30\nmotion_hz = 100\n[cognition]\nmodules = ["A", "B"]\n[cognition.providers]\nX = "A"\n')
    write(tmp_path / "platform" / "sim.toml", '[runtime]\ncognition_hz = 20\n[cognition.providers]\nY = "B"\n')
    write(tmp_path / "robot" / "nao1.toml", '[cognition]\nmodules = ["C"]\n')
    write(tmp_path / "private" / "private.toml", "[runtime]\nmotion_hz = 50\n")
    return tmp_path


def test_layers_override_in_order(config_dir: Path) -> None:
    config = load_config(config_dir, "sim", "nao1")
    assert config["runtime"] == {"cognition_hz": 20, "motion_hz": 50}
    assert config["cognition"]["modules"] == ["C"]  # lists are replaced whole
    assert config["cognition"]["providers"] == {"X": "A", "Y": "B"}  # tables merge
    assert [Path(p).name for p in config["_sources"]] == ["general.toml", "sim.toml", "nao1.toml", "private.toml"]


def test_missing_layers_are_skipped(config_dir: Path) -> None:
    config = load_config(config_dir, "other")
    assert config["runtime"]["cognition_hz"] == 30 and config["cognition"]["modules"] == ["A", "B"]


def test_overrides_come_last_and_parse_toml_values(config_dir: Path) -> None:
    config = load_config(config_dir, "sim", overrides=["runtime.cognition_hz=15", 'cognition.modules=["Z"]', "parameters.M.name=hello"])
    assert config["runtime"]["cognition_hz"] == 15
    assert config["cognition"]["modules"] == ["Z"]
    assert config["parameters"]["M"]["name"] == "hello"


@pytest.mark.parametrize("text", ["novalue", "=3", "a..b=1", ""])
def test_malformed_overrides_say_what_is_expected(text: str) -> None:
    with pytest.raises(ConfigError, match="KEY=VALUE"):
        parse_override(text)


def test_override_through_a_value_fails() -> None:
    with pytest.raises(ConfigError, match="is a value, not a table"):
        apply_overrides({"runtime": {"cognition_hz": 30}}, ["runtime.cognition_hz.x=1"])


def test_invalid_toml_names_the_file(tmp_path: Path) -> None:
    write(tmp_path / "general.toml", "[runtime\n")
    with pytest.raises(ConfigError, match="general.toml: not valid TOML"):
        load_config(tmp_path, "sim")


def test_missing_folder_is_an_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="does not exist"):
        load_config(tmp_path / "nope", "sim")


def test_context_section_checks_types() -> None:
    assert context_section({}, "cognition") == {"modules": [], "disabled": [], "providers": {}}
    with pytest.raises(ConfigError, match="cognition.modules takes a list of module names, got"):
        context_section({"cognition": {"modules": "A"}}, "cognition")
    with pytest.raises(ConfigError, match="providers takes a table of representation names to module names"):
        context_section({"motion": {"providers": {"X": 1}}}, "motion")


def test_store_private_keeps_other_values(config_dir: Path) -> None:
    store_private(config_dir, ["cognition", "providers", "BallModel"], "SimpleBallModeler")
    config = load_config(config_dir, "sim")
    assert config["cognition"]["providers"]["BallModel"] == "SimpleBallModeler"
    assert config["runtime"]["motion_hz"] == 50


def test_merge_does_not_modify_its_inputs() -> None:
    base = {"a": {"b": 1}}
    merged = merge(base, {"a": {"c": 2}})
    assert base == {"a": {"b": 1}} and merged == {"a": {"b": 1, "c": 2}}


toml_keys = st.text(alphabet="abcdefgxyz_0123", min_size=1, max_size=8)
toml_scalars = st.one_of(
    st.booleans(), st.integers(-(2**40), 2**40), st.floats(allow_nan=False, allow_infinity=False), st.text(max_size=10)
)
toml_tables = st.recursive(
    st.dictionaries(toml_keys, st.one_of(toml_scalars, st.lists(toml_scalars.filter(lambda v: not isinstance(v, bool)), max_size=3)), max_size=4),
    lambda inner: st.dictionaries(toml_keys, inner, max_size=3),
    max_leaves=10,
)


@given(toml_tables)
def test_dump_toml_round_trips(data: dict) -> None:
    assert tomllib.loads(dump_toml(data)) == data


# ------------------------------------------------------------------- adding and removing modules in TOML
@pytest.fixture
def layered(tmp_path: Path) -> Path:
    """Four layers, each editing the module list it inherits."""
    write(tmp_path / "general.toml", '[cognition]\nmodules = ["A", "B", "C"]\n[motion]\nmodules = ["M"]\n')
    write(tmp_path / "platform" / "sim.toml", '[cognition]\nadd = ["D"]\nremove = ["A"]\n')
    write(tmp_path / "robot" / "nao1.toml", '[cognition]\nadd = ["E"]\n[motion]\nadd = ["N"]\n')
    write(tmp_path / "private" / "private.toml", '[cognition]\nremove = ["B"]\n')
    return tmp_path


def test_layers_add_and_remove_modules_without_restating_the_list(layered: Path) -> None:
    config = load_config(layered, "sim", "nao1")
    assert config["cognition"]["modules"] == ["C", "D", "E"]
    assert config["motion"]["modules"] == ["M", "N"]
    assert "add" not in config["cognition"] and "remove" not in config["cognition"]  # applied, not left for later layers


def test_disable_and_enable_edit_the_disabled_list_a_layer_inherits(layered: Path) -> None:
    write(layered / "platform" / "sim.toml", '[cognition]\ndisabled = ["C", "D"]\n')
    write(layered / "private" / "private.toml", '[cognition]\ndisable = ["A", "C"]\nenable = ["D", "X"]\n')
    config = load_config(layered, "sim")
    assert config["cognition"]["disabled"] == ["C", "A"]  # D enabled again; enabling what is not disabled is no error
    assert "disable" not in config["cognition"] and "enable" not in config["cognition"]
    write(layered / "platform" / "sim.toml", "")
    assert load_config(layered, "sim")["cognition"]["disabled"] == ["A", "C"]  # another platform: only the own choices
    write(layered / "private" / "private.toml", '[cognition]\ndisable = "A"\n')
    with pytest.raises(ConfigError, match=r'disable takes a list of module names, e.g. disable = \["GoalPostDetector"\]'):
        load_config(layered, "sim")


def test_a_layer_that_restates_the_list_starts_over_and_its_own_edits_apply_to_it(layered: Path) -> None:
    write(layered / "robot" / "nao1.toml", '[cognition]\nmodules = ["X", "Y"]\nadd = ["Z"]\nremove = ["X"]\n')
    write(layered / "private" / "private.toml", "")
    assert load_config(layered, "sim", "nao1")["cognition"]["modules"] == ["Y", "Z"]


def test_adding_a_listed_module_keeps_one_entry(layered: Path) -> None:
    write(layered / "robot" / "nao1.toml", '[cognition]\nadd = ["C", "F"]\n')
    assert load_config(layered, "sim", "nao1")["cognition"]["modules"] == ["C", "D", "F"]


def test_edits_in_several_config_folders_and_in_set_overrides_apply_in_order(layered: Path, tmp_path: Path) -> None:
    user = tmp_path / "user"
    write(user / "general.toml", '[cognition]\nadd = ["U"]\n')
    config = load_config([layered, user], "sim", overrides=['cognition.remove=["D"]', 'motion.add=["O"]'])
    assert config["cognition"]["modules"] == ["C", "U"]  # the private layer of the first folder removed B
    assert config["motion"]["modules"] == ["M", "O"]


def test_removing_a_module_that_is_not_listed_names_the_file_and_the_closest_name(layered: Path) -> None:
    write(layered / "robot" / "nao1.toml", '[cognition]\nremove = ["C", "Dd"]\n')
    with pytest.raises(ConfigError, match=r"nao1.toml: \[cognition\] remove: Dd is not in the module list.*did you mean 'D'"):
        load_config(layered, "sim", "nao1")


@pytest.mark.parametrize(("text", "message"), [
    ('[cognition]\nad = ["D"]\n', r"\[cognition\] ad is not a setting; did you mean 'add'"),
    ('[cognition]\nadd = "D"\n', r"\[cognition\] add takes a list of module names"),
    ('[motion]\nremove = [1]\n', r"\[motion\] remove takes a list of module names"),
])
def test_wrong_module_edits_are_errors_that_say_what_would_be_right(layered: Path, text: str, message: str) -> None:
    write(layered / "robot" / "nao1.toml", text)
    with pytest.raises(ConfigError, match=message):
        load_config(layered, "sim", "nao1")


def test_store_private_keeps_the_users_comments_and_layout(tmp_path: Path) -> None:
    """The private layer is the user's file: a stored value changes that value and nothing else."""
    private = tmp_path / "private" / "private.toml"
    text = ('# my robot at home: the carpet is slippery\n[parameters.WalkingEngine]\nodometry_scale = 0.9  # measured 2026-11-20\n\n'
            '[cognition]\ndisabled = ["GoalPostDetector"]   # no goals in the lab\n')
    write(private, text)
    store_private(tmp_path, ["parameters", "HeadMotion", "max_speed"], 2.5)
    store_private(tmp_path, ["parameters", "WalkingEngine", "odometry_scale"], 0.92)
    after = private.read_text()
    for kept in ("# my robot at home: the carpet is slippery", "# measured 2026-11-20", "# no goals in the lab"):
        assert kept in after
    assert tomllib.loads(after) == {"parameters": {"WalkingEngine": {"odometry_scale": 0.92}, "HeadMotion": {"max_speed": 2.5}},
                                    "cognition": {"disabled": ["GoalPostDetector"]}}


@pytest.mark.parametrize("text", ["Motion:WalkingEngine", "vision:BallDetector", ":BallDetector"])
def test_a_module_edit_for_no_context_is_an_error_naming_the_contexts(text: str) -> None:
    from tafel.core.framework.config import edit_modules

    with pytest.raises(ConfigError) as error:
        edit_modules({}, add=[text])
    assert str(error.value) == f"--add-module {text}: CONTEXT takes cognition or motion, got {text.split(':')[0]!r}"


def test_a_module_edit_without_a_context_says_the_form() -> None:
    from tafel.core.framework.config import edit_modules

    with pytest.raises(ConfigError, match=r"^--remove-module takes CONTEXT:MODULE with CONTEXT cognition or motion, "
                                          r"e.g. cognition:BallDetector, got 'BallDetector'$"):
        edit_modules({}, remove=["BallDetector"])
