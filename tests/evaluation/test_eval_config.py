"""Evaluation protocols as files: the shipped paper config, its checks, and ``chain eval
--config`` sending what the config says (sampling, budgets, both protocols) to a model."""

from __future__ import annotations

from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.evaluation.eval_config import ConfigError, config_names, load_config
from chaingeo.evaluation.logs import RunLog
from tests.support.fake_openai import Script, fake_openai
from tests.support.harness import chain_eval, openai_args, suite_folder


def test_the_paper_config_is_shipped_and_says_the_papers_protocol() -> None:
    assert "chain-paper" in config_names()
    c = load_config("chain-paper")
    assert c.protocols == ("interactive", "oneshot")
    assert (c.temperature, c.top_p, c.history_window, c.images) == (0.6, 0.95, 5, True)
    assert c.max_steps is None  # the levels' own 30-60 step budgets
    assert c.protocol("oneshot").name == "oneshot"
    assert c.protocol("interactive", history_window=2).history_window == 2


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("protocols = ['closed']", "protocols"),
        ("history_window = -1", "out of range"),
        ("temperature = 'hot'", "wrong type"),
        ("images = 1", "wrong type"),
        ("samples = true", "wrong type"),
        ("colour = 'red'", "unknown field"),
        ("this is not toml", "not TOML"),
    ],
)
def test_bad_configs_are_named_errors(tmp_path: Path, text: str, match: str) -> None:
    f = tmp_path / "mine.toml"
    f.write_text(text)
    with pytest.raises(ConfigError, match=match):
        load_config(f)


def test_unknown_config_lists_the_shipped_ones() -> None:
    with pytest.raises(ConfigError, match="chain-paper"):
        load_config("no-such-config")


def test_chain_eval_help_lists_the_configs(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["eval", "--help"])
    assert "chain-paper" in capsys.readouterr().out


def test_chain_eval_with_the_paper_config(tmp_path: Path) -> None:
    """Both protocols, the paper's sampling on every request, a config budget on every level."""
    suite = suite_folder(tmp_path, 2)
    mine = tmp_path / "short.toml"
    mine.write_text(
        "protocols = ['interactive', 'oneshot']\ntemperature = 0.6\ntop_p = 0.95\nmax_steps = 3\n"
    )
    for config in ("chain-paper", str(mine)):
        script = Script()  # answers finish to everything
        out = tmp_path / Path(config).stem
        with fake_openai(script) as url:
            assert chain_eval(suite, out, *openai_args(url), "--config", config) == 0
        assert script.problems == []
        runs = sorted(p.name for p in out.iterdir() if not p.name.endswith(".lock"))
        assert runs == ["fake-interactive", "fake-oneshot"]
        bodies = [r["body"] for r in script.requests]
        assert {(b["temperature"], b["top_p"]) for b in bodies} == {(0.6, 0.95)}
        budgets = {r["max_steps"] for r in RunLog(out / "fake-interactive").records()}
        assert budgets == ({3} if config == str(mine) else {30})  # the levels' own: 30
