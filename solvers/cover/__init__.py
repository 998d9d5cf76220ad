"""Exact cover: the problem compiled to rows (placements, problem), the search engines (bit-board,
MRV bit-board, dancing links) behind one resumable search, and packings counted, listed and
drawn at random (:mod:`chaingeo.solvers.cover.packings`). Knows nothing of motion."""
