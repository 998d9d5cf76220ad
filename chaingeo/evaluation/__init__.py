"""The evaluation harness: agents (:mod:`.agents`) play levels in episodes (:mod:`.episode`) run
by :func:`evaluate` (:mod:`.runner`), judged (:mod:`.judges`), logged, measured
(:mod:`.metrics`) and reported (:mod:`.report`).

Its entry points are exported here and imported on first use: ``evaluate``, ``RunConfig``,
``ProtocolConfig``, the agent and judge registries (``register_agent``, ``make_agent``,
``register_judge``, ``make_judge``), ``summarize``, ``load_run`` and ``write_report``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Final

from chaingeo.core.lazy import lazy_exports

if TYPE_CHECKING:  # the real types for mypy and editors; at run time see _LAZY
    from chaingeo.evaluation.agents.base import Agent, AgentSpec
    from chaingeo.evaluation.agents.registry import make_agent, register_agent
    from chaingeo.evaluation.episode import Outcome, ProtocolConfig
    from chaingeo.evaluation.judges.registry import make_judge, register_judge
    from chaingeo.evaluation.judges.selection import Judge
    from chaingeo.evaluation.metrics import Summary, summarize
    from chaingeo.evaluation.report.tables import load_run, write_report
    from chaingeo.evaluation.runner import RunConfig, evaluate
    from chaingeo.evaluation.usage import PriceTable

#: Public name -> "module:attribute", imported on first use (:mod:`chaingeo.core.lazy`).
_LAZY: Final = {
    "Agent": "chaingeo.evaluation.agents.base:Agent",
    "AgentSpec": "chaingeo.evaluation.agents.base:AgentSpec",
    "Judge": "chaingeo.evaluation.judges.selection:Judge",
    "Outcome": "chaingeo.evaluation.episode:Outcome",
    "PriceTable": "chaingeo.evaluation.usage:PriceTable",
    "ProtocolConfig": "chaingeo.evaluation.episode:ProtocolConfig",
    "RunConfig": "chaingeo.evaluation.runner:RunConfig",
    "Summary": "chaingeo.evaluation.metrics:Summary",
    "evaluate": "chaingeo.evaluation.runner:evaluate",
    "load_run": "chaingeo.evaluation.report.tables:load_run",
    "make_agent": "chaingeo.evaluation.agents.registry:make_agent",
    "make_judge": "chaingeo.evaluation.judges.registry:make_judge",
    "register_agent": "chaingeo.evaluation.agents.registry:register_agent",
    "register_judge": "chaingeo.evaluation.judges.registry:register_judge",
    "summarize": "chaingeo.evaluation.metrics:summarize",
    "write_report": "chaingeo.evaluation.report.tables:write_report",
}

__all__ = [
    "Agent",
    "AgentSpec",
    "Judge",
    "Outcome",
    "PriceTable",
    "ProtocolConfig",
    "RunConfig",
    "Summary",
    "evaluate",
    "load_run",
    "make_agent",
    "make_judge",
    "register_agent",
    "register_judge",
    "summarize",
    "write_report",
]

if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, _LAZY)
