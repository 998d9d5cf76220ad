"""Token usage as additive records, and what it costs (prices come from a data file, not code).

A :class:`Usage` is what one model call consumed; records add up (per step, per episode, per
run) with ``+``. Conventions follow the OpenAI chat-completions ``usage`` block: reasoning tokens
are part of the output tokens and cached tokens are part of the input tokens, so the total is
``input + output`` and nothing is counted twice.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any


@dataclass(frozen=True)
class Usage:
    """Tokens consumed by one or more model calls (all counts are additive)."""

    input_tokens: int = 0
    output_tokens: int = 0
    reasoning_tokens: int = 0  # included in output_tokens
    cached_tokens: int = 0  # included in input_tokens
    calls: int = 0

    def __add__(self, other: Usage) -> Usage:
        return Usage(
            self.input_tokens + other.input_tokens,
            self.output_tokens + other.output_tokens,
            self.reasoning_tokens + other.reasoning_tokens,
            self.cached_tokens + other.cached_tokens,
            self.calls + other.calls,
        )

    @property
    def total_tokens(self) -> int:
        return self.input_tokens + self.output_tokens

    def to_json(self) -> dict[str, int]:
        return {
            "input_tokens": self.input_tokens,
            "output_tokens": self.output_tokens,
            "reasoning_tokens": self.reasoning_tokens,
            "cached_tokens": self.cached_tokens,
            "calls": self.calls,
        }

    @staticmethod
    def from_json(obj: Mapping[str, Any]) -> Usage:
        return Usage(
            int(obj.get("input_tokens", 0)),
            int(obj.get("output_tokens", 0)),
            int(obj.get("reasoning_tokens", 0)),
            int(obj.get("cached_tokens", 0)),
            int(obj.get("calls", 0)),
        )

    @staticmethod
    def from_openai(obj: Mapping[str, Any] | None) -> Usage:
        """Read an OpenAI-style ``usage`` block (missing fields count as zero). Reasoning and
        cached tokens come from ``completion_tokens_details``/``prompt_tokens_details``, or from
        the ``output_``/``input_tokens_details`` some servers write, or from a bare top-level
        ``reasoning_tokens``/``cached_tokens``."""
        if not isinstance(obj, Mapping):
            return Usage(calls=1)
        return Usage(
            input_tokens=_count(obj.get("prompt_tokens")),
            output_tokens=_count(obj.get("completion_tokens")),
            reasoning_tokens=_detail(
                obj, ("completion_tokens_details", "output_tokens_details"), "reasoning_tokens"
            ),
            cached_tokens=_detail(
                obj, ("prompt_tokens_details", "input_tokens_details"), "cached_tokens"
            ),
            calls=1,
        )


def _detail(obj: Mapping[str, Any], blocks: tuple[str, ...], key: str) -> int:
    for block in blocks:
        details = obj.get(block)
        if isinstance(details, Mapping) and key in details:
            return _count(details[key])
    return _count(obj.get(key))


def _count(value: Any) -> int:
    return value if isinstance(value, int) and not isinstance(value, bool) and value > 0 else 0


def total_usage(records: Iterable[Usage]) -> Usage:
    out = Usage()
    for u in records:
        out = out + u
    return out


@dataclass(frozen=True)
class Price:
    """USD per one million tokens."""

    input: float
    output: float
    cached_input: float | None = None  # None: cached tokens cost the input rate

    def cost(self, usage: Usage) -> float:
        cached_rate = self.input if self.cached_input is None else self.cached_input
        fresh = usage.input_tokens - usage.cached_tokens
        return (
            fresh * self.input
            + usage.cached_tokens * cached_rate
            + usage.output_tokens * self.output
        ) / 1_000_000


class PriceError(ValueError):
    """A price file that cannot be read: which file and why."""


class PriceTable:
    """Model name -> :class:`Price`, from the shipped table plus optional user files."""

    def __init__(self, prices: Mapping[str, Price]) -> None:
        self.prices = dict(prices)

    @staticmethod
    def load(*extra: str | Path) -> PriceTable:
        """The shipped ``chaingeo/evaluation/prices.json``, then each extra file on top (later
        wins)."""
        text = resources.files("chaingeo.evaluation").joinpath("prices.json").read_text("utf-8")
        prices = _parse_prices(json.loads(text), "chaingeo/evaluation/prices.json")
        for path in extra:
            try:
                data = json.loads(Path(path).read_text("utf-8"))
            except (OSError, json.JSONDecodeError) as e:
                raise PriceError(f"{path}: cannot read price table: {e}") from None
            prices.update(_parse_prices(data, str(path)))
        return PriceTable(prices)

    def get(self, model: str) -> Price | None:
        """Exact name first, then the name without a provider prefix (``openai/gpt-4o``)."""
        if model in self.prices:
            return self.prices[model]
        return self.prices.get(model.rsplit("/", 1)[-1])

    def cost(self, model: str | None, usage: Usage) -> float | None:
        """USD for ``usage``: 0 when no tokens were used, None when the model has no price."""
        if usage.total_tokens == 0:
            return 0.0
        price = self.get(model) if model else None
        return None if price is None else price.cost(usage)


def _parse_prices(data: Any, source: str) -> dict[str, Price]:
    models = data.get("models") if isinstance(data, dict) else None
    if not isinstance(models, dict):
        raise PriceError(f"{source}: expected an object with a 'models' object")
    out: dict[str, Price] = {}
    for name, entry in models.items():
        if not isinstance(entry, dict):
            raise PriceError(f"{source}: models.{name}: expected an object")
        values: dict[str, float | None] = {}
        for key in ("input", "output", "cached_input"):
            v = entry.get(key)
            if v is None and key == "cached_input":
                values[key] = None
                continue
            if isinstance(v, bool) or not isinstance(v, int | float) or v < 0:
                raise PriceError(f"{source}: models.{name}.{key}: expected a price >= 0")
            values[key] = float(v)
        inp, outp = values["input"], values["output"]
        assert inp is not None and outp is not None
        out[str(name)] = Price(inp, outp, values["cached_input"])
    return out
