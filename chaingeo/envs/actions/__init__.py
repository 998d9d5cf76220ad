"""Actions: their types and canonical text (:mod:`.types`), lazy action lists, the parser of agent
text (:mod:`.parse`, with CHAIN's dialect and turn words) and the Gymnasium text space."""
