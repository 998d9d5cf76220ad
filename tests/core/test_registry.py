"""The one Registry: its contract (property-tested against a plain model) and each registry of
the project refusing a taken name and listing the known ones for an unknown name."""

from __future__ import annotations

from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from chaingeo.benchmarks import BENCHMARKS
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.registry import DuplicateNameError, Registry, UnknownNameError
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.agents.registry import AGENTS, make_agent, register_agent
from chaingeo.evaluation.judges.registry import JUDGES, make_judge, register_judge
from chaingeo.generator.config import CONFIGS, PuzzleConfig, get_config, register_config
from chaingeo.generator.layouts import LAYOUTS
from chaingeo.generator.puzzle import SHAPES, shape_family

NAMES = st.text(st.characters(codec="ascii", categories=["L", "N", "P"]), min_size=1, max_size=6)


@given(st.lists(st.tuples(NAMES, st.integers()), max_size=30), NAMES)
def test_registry_behaves_like_a_write_once_ordered_table(
    ops: list[tuple[str, int]], probe: str
) -> None:
    reg: Registry[int] = Registry("widget")
    model: dict[str, int] = {}
    for name, item in ops:
        if name in model:
            with pytest.raises(DuplicateNameError, match="already registered") as refused:
                reg.register(name, item)
            assert refused.value.name == name and repr(name) in str(refused.value)
        else:
            assert reg.register(name, item) == item
            model[name] = item
    assert reg.names() == tuple(model) == tuple(reg)  # registration order, first one kept
    assert reg.items() == tuple(model.items()) and len(reg) == len(model)
    assert all(reg.get(n) == v and n in reg for n, v in model.items())
    if probe not in model:
        with pytest.raises(UnknownNameError) as unknown:
            reg.get(probe)
        message = str(unknown.value)
        assert message.startswith(f"unknown widget {probe!r}; known: ")
        assert message.endswith(", ".join(sorted(model)) or "none")
        assert isinstance(unknown.value, ChainGeoError) and isinstance(unknown.value, ValueError)


@given(NAMES, st.integers(), st.integers())
def test_decorator_and_temporary_registration(name: str, first: int, second: int) -> None:
    reg: Registry[Any] = Registry("widget")

    @reg.register(name)
    def made() -> int:
        return first

    assert reg.get(name) is made and made() == first
    with pytest.raises(DuplicateNameError):
        reg.register(name)(lambda: second)
    assert reg.unregister(name) is made and name not in reg
    with reg.registered(name, second):
        assert reg.get(name) == second
    assert reg.names() == ()


REGISTRIES: list[Registry[Any]] = [AGENTS, JUDGES, CONFIGS, SHAPES, LAYOUTS, BENCHMARKS]


@pytest.mark.parametrize("registry", REGISTRIES, ids=lambda r: r.kind)
def test_each_registry_refuses_a_taken_name_and_lists_known_ones(registry: Registry[Any]) -> None:
    names = registry.names()
    assert len(names) >= 4
    taken = names[len(names) // 2]
    before = registry.get(taken)
    with pytest.raises(DuplicateNameError, match=repr(taken)):
        registry.register(taken, object())
    assert registry.get(taken) is before and registry.names() == names
    with pytest.raises(UnknownNameError) as unknown:
        registry.get("no-such-name")
    assert "'no-such-name'" in str(unknown.value)
    assert str(unknown.value).endswith("known: " + ", ".join(sorted(names)))


def test_the_public_functions_refuse_the_same_way() -> None:
    with pytest.raises(DuplicateNameError, match="'oracle'"):
        register_agent("oracle", lambda spec: make_agent(AgentSpec("random")))
    with pytest.raises(ValueError, match="unknown agent 'nope'; known: command, greedy"):
        make_agent(AgentSpec("nope"))
    with pytest.raises(DuplicateNameError, match="'vote'"):
        register_judge("vote", lambda options: make_judge("first"))
    with pytest.raises(ValueError, match="unknown judge 'nope'; known: first, model"):
        make_judge("nope")
    with pytest.raises(ValueError, match="no stacking config named 'nope'; known: 2x2x2-easy"):
        get_config("nope")
    with pytest.raises(DuplicateNameError, match="'2x2x2-easy'"):
        register_config("2x2x2-easy", get_config("2x2x3-easy"))


@pytest.mark.parametrize(
    ("shape", "max_group", "family"),
    [
        ("burr6x8u", None, "standard"),
        ("cube4", None, "cube"),
        ("maze7", 1, "maze"),
        ("burr12", 1, "tower"),
        ("burr12", None, "layout"),
        ("burr6", 1, "layout"),
    ],
)
def test_a_shape_name_picks_its_family(shape: str, max_group: int | None, family: str) -> None:
    assert shape_family(PuzzleConfig(shape=shape, max_group=max_group)) is SHAPES.get(family)
