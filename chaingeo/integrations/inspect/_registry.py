"""inspect_ai's entry point (``chaingeo = chaingeo.integrations.inspect._registry``): importing
this module registers the task ``chaingeo/chain``."""

from chaingeo.integrations.inspect.task import chain

__all__ = ["chain"]
