"""The OpenEnv environment: one per WebSocket session, playing one level at a time.

``reset`` takes ``level`` (an id the server was started with), ``seed``, ``episode_id`` and the
options of :func:`~chaingeo.integrations.serve.session.read_options`; in a study, ``participant``
instead of ``level`` (the study assigns it). ``step`` takes a :class:`ChainAction`. OpenEnv runs
every session's calls on one shared thread (``REQUIRES_SINGLE_THREAD_EXECUTOR``): the engine's
caches are per process and were never made thread-safe, and under the GIL the work is serial
anyway.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from openenv.core.env_server.interfaces import Environment
from openenv.core.env_server.types import EnvironmentMetadata

from chaingeo.core.level import Level
from chaingeo.integrations.serve.errors import (
    NoEpisodeError,
    RequestError,
    StudyError,
    UnknownLevelIdError,
)
from chaingeo.integrations.serve.models import ChainAction, ChainObservation, ChainState
from chaingeo.integrations.serve.session import Play, read_options

if TYPE_CHECKING:
    from chaingeo.integrations.serve.study import Study

MAX_EPISODE_ID_CHARS = 255


@dataclass
class Catalog:
    """The levels a server plays, by id (sorted), and the study it runs, if any."""

    levels: dict[str, Level]
    study: Study | None = None
    default: str = field(init=False, default="")

    def __post_init__(self) -> None:
        if not self.levels:
            raise RequestError("the server has no levels")
        self.levels = dict(sorted(self.levels.items()))
        self.default = next(iter(self.levels))

    def level(self, level_id: Any) -> Level:
        if not isinstance(level_id, str) or level_id not in self.levels:
            shown = repr(level_id)[:80]
            raise UnknownLevelIdError(f"no level {shown} on this server; GET / lists them")
        return self.levels[level_id]


class ChainEnvironment(Environment[ChainAction, ChainObservation, ChainState]):  # type: ignore[misc]
    """A level's state machine behind OpenEnv's reset / step / state."""

    SUPPORTS_CONCURRENT_SESSIONS = True
    REQUIRES_SINGLE_THREAD_EXECUTOR = True

    def __init__(self, catalog: Catalog) -> None:
        super().__init__()
        self.catalog = catalog
        self.play: Play | None = None
        self.episode_id: str | None = None
        self.participant: str | None = None

    def reset(
        self, seed: int | None = None, episode_id: str | None = None, **options: Any
    ) -> ChainObservation:
        if seed is not None and (isinstance(seed, bool) or not isinstance(seed, int) or seed < 0):
            raise RequestError("seed must be a whole number >= 0")
        if seed is not None and seed >= 2**63:
            raise RequestError("seed must be below 2**63")
        if episode_id is not None and (
            not isinstance(episode_id, str) or len(episode_id) > MAX_EPISODE_ID_CHARS
        ):
            raise RequestError(f"episode_id must be text of at most {MAX_EPISODE_ID_CHARS}")
        level, participant, rest = self._level(options)
        opts = read_options(rest)
        study = self.catalog.study
        agent = "human" if study is not None else "client"
        play = Play(level, opts, seed, hide_optimal=study is not None, agent=agent)
        first = play.observation()  # may still refuse: nothing has changed yet
        self._abandon()
        self.play, self.episode_id, self.participant = play, episode_id, participant
        return first

    def _level(self, options: Mapping[str, Any]) -> tuple[Level, str | None, dict[str, Any]]:
        """The level to play, the participant (studies), and the remaining options."""
        rest = {k: v for k, v in options.items() if k not in ("level", "participant")}
        study = self.catalog.study
        if study is None:
            if "participant" in options:
                raise StudyError("this server runs no study; reset with a level")
            return self.catalog.level(options.get("level", self.catalog.default)), None, rest
        if "level" in options:
            raise StudyError("in a study the levels are assigned; reset with a participant id")
        participant = study.check_participant(options.get("participant"))
        level = study.next_level(participant)
        return level, participant, rest

    def step(
        self, action: ChainAction, timeout_s: float | None = None, **kwargs: Any
    ) -> ChainObservation:
        if self.play is None:
            raise NoEpisodeError("no episode yet: reset first")
        self.play.step(action)
        if self.play.done:
            self._record()
        return self.play.observation()

    @property
    def state(self) -> ChainState:
        play = self.play
        if play is None:
            return ChainState(episode_id=self.episode_id)
        return ChainState(
            episode_id=self.episode_id,
            step_count=int(play.state.steps_used),
            level_id=play.level.id,
            steps=int(play.state.steps_used),
            key=play.key(),
            done=play.done,
            success=bool(play.state.is_success()),
        )

    def _record(self) -> None:
        """A study writes each episode once, when it ends or is left."""
        study, play = self.catalog.study, self.play
        if study is not None and play is not None and self.participant is not None:
            study.record(self.participant, play, self.episode_id)
            self.participant = None  # recorded: not again

    def _abandon(self) -> None:
        if self.play is not None and not self.play.done and self.play.steps:
            self._record()

    def close(self) -> None:
        self._abandon()

    def get_metadata(self) -> EnvironmentMetadata:
        return EnvironmentMetadata(
            name="chaingeo",
            description=(
                "CHAIN-geo: interlocking puzzles and 3D stacking on exact discrete geometry. "
                f"{len(self.catalog.levels)} levels; GET / lists them, /play/<id> plays one."
            ),
            version=_version(),
        )


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("chaingeo")
    except PackageNotFoundError:
        return "0"
