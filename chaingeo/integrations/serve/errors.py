"""The server's refusals: each a :class:`ChainGeoError` with the HTTP status it answers with.

Over HTTP the status is the response's; over a WebSocket, OpenEnv answers an error frame whose
message starts with the error's class name, and the session goes on unchanged.
"""

from __future__ import annotations

from chaingeo.core.errors import ChainGeoError


class ServeError(ChainGeoError, ValueError):
    """A request the server refuses (400 unless a subclass says otherwise)."""

    status = 400

    @property
    def reason(self) -> str:
        """The message without the class name (``str()`` leads with it: OpenEnv's WebSocket
        error frames carry only ``str(exc)``, and a client should still see which error)."""
        return super().__str__()

    def __str__(self) -> str:
        return f"{type(self).__name__}: {self.reason}"


class NotFoundError(ServeError, LookupError):
    """A path, static file or level this server does not have."""

    status = 404


class TooLargeError(ServeError):
    """A request body past :data:`chaingeo.core.limits.MAX_REQUEST_BYTES`."""

    status = 413


class RequestError(ServeError):
    """A reset option or request field of the wrong kind or out of range."""


class UnknownLevelIdError(NotFoundError):
    """A level id the server was not started with."""


class NoEpisodeError(ServeError):
    """A step or an action before any reset, or after the episode ended."""

    status = 409


class SessionLimitError(ServeError):
    """A session past its bounds (messages, bytes): open a new one."""

    status = 429


class AuthError(ServeError):
    """A missing or wrong bearer token."""

    status = 401


class StudyError(ServeError):
    """A study request that does not fit the study (its levels are assigned, not chosen)."""

    status = 403
