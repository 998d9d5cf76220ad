"""Token usage as additive records, and what it costs (prices come from a data file, not code).

A :class:`Usage` is what one model call consumed; records add up (per step, per episode, per
run) with ``+``. Conventions follow the OpenAI chat-completions ``usage`` block: reasoning tokens
are part of the output tokens and cached tokens are part of the input tokens, so the total is
``input + output`` and nothing is counted twice.

A server's usage block is untrusted: each field must be a whole number from 0 to
:data:`~chaingeo.core.limits.MAX_USAGE_TOKENS` (:class:`UsageError` otherwise, which the agent
reports as a protocol error of the server), and prices are finite and bounded, so no cost is
ever infinite or NaN.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any, Final

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.files import UnreadableFile, read_json

#: The largest count a cost multiplies (int64, what any real counter holds): with prices at
#: most :data:`~chaingeo.core.limits.MAX_PRICE_USD` every cost is a finite float.
_MAX_PRICED: Final = 2**63 - 1


class UsageError(ChainGeoError, ValueError):
    """A usage block that is not whole, non-negative, bounded token counts; names the field."""


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

    def __sub__(self, other: Usage) -> Usage:
        """What was spent since ``other`` (an earlier reading of the same counter)."""
        return Usage(
            self.input_tokens - other.input_tokens,
            self.output_tokens - other.output_tokens,
            self.reasoning_tokens - other.reasoning_tokens,
            self.cached_tokens - other.cached_tokens,
            self.calls - other.calls,
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
        ``reasoning_tokens``/``cached_tokens``. :class:`UsageError` for a field that is not a
        whole number of tokens within bounds, or a block that is not an object."""
        if obj is None:
            return Usage(calls=1)
        if not isinstance(obj, Mapping):
            raise UsageError(f"usage is {_shown(obj)}, not an object")
        return Usage(
            input_tokens=_count(obj.get("prompt_tokens"), "prompt_tokens"),
            output_tokens=_count(obj.get("completion_tokens"), "completion_tokens"),
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
            return _count(details[key], f"{block}.{key}")
    return _count(obj.get(key), key)


def _shown(value: Any) -> str:
    text = repr(value) if not isinstance(value, int) or value < 10**20 else "a huge number"
    return text if len(text) <= 40 else text[:37] + "..."


def _count(value: Any, where: str) -> int:
    """A token count: absent or null is 0; else a whole number within the bound, checked
    before any arithmetic sees it."""
    if value is None:
        return 0
    if isinstance(value, float) and value.is_integer():  # 12.0 from some proxies: still whole
        value = int(value) if abs(value) <= limits.MAX_USAGE_TOKENS else value
    ok = isinstance(value, int) and not isinstance(value, bool)
    if not ok or not 0 <= value <= limits.MAX_USAGE_TOKENS:
        raise UsageError(
            f"usage.{where} is {_shown(value)}: expected a whole number of tokens from 0 to"
            f" {limits.MAX_USAGE_TOKENS}"
        )
    return int(value)


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
        """USD, finite whatever the counts (each capped at int64, cached within input)."""
        cached_rate = self.input if self.cached_input is None else self.cached_input
        inputs = min(max(usage.input_tokens, 0), _MAX_PRICED)
        cached = min(max(usage.cached_tokens, 0), inputs)
        outputs = min(max(usage.output_tokens, 0), _MAX_PRICED)
        return (
            float(inputs - cached) * self.input
            + float(cached) * cached_rate
            + float(outputs) * self.output
        ) / 1_000_000


class PriceError(ChainGeoError, ValueError):
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
            try:  # the one bounded JSON reader: a regular file, size, depth and digits first
                data = read_json(path, limits.MAX_FILE_BYTES)
            except UnreadableFile as e:
                raise PriceError(f"{path}: cannot read price table: {e.reason}") from None
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
            if (
                isinstance(v, bool)
                or not isinstance(v, int | float)
                or not 0 <= v <= limits.MAX_PRICE_USD  # also refuses NaN and infinities
            ):
                raise PriceError(
                    f"{source}: models.{name}.{key}: expected a price from 0 to"
                    f" {limits.MAX_PRICE_USD:g} (USD per 1M tokens)"
                )
            values[key] = float(v)
        inp, outp = values["input"], values["output"]
        assert inp is not None and outp is not None
        out[str(name)] = Price(inp, outp, values["cached_input"])
    return out
