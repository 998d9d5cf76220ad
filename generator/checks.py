"""Re-verify a generated stacking level against the rules of the configuration that made it.

A test oracle that ships with the package on purpose: the suite tests run it on every shipped
stacking level, and whoever generates levels with their own configuration can check the
output against the generator's promises the same way.

The level loader already proves the file sound (connected pieces, an exact fill of the box by
rotations of the pieces, a legal placing order, the signature). This adds the generator's own
promises: piece sizes, no filled 2x3 face, the mode's shape rules, no isolated piece, a linear
assembly, and an independent exact-cover search that packs the pieces with at least the
recorded search effort.
"""

from __future__ import annotations

from chaingeo.core.level import Level, StackingSolution
from chaingeo.generator import packing
from chaingeo.generator.assembly import assembly_order, has_isolated_piece
from chaingeo.generator.config import StackingConfig
from chaingeo.generator.partition import PieceRules, is_planar
from chaingeo.generator.stacking import piece_problem


def _two_equal_sides(extent: tuple[int, int, int]) -> bool:
    a, b, c = sorted(extent)
    return a == b or b == c


def level_problems(level: Level, config: StackingConfig) -> list[str]:
    """Every broken promise of ``level`` under ``config`` (empty: the level is sound)."""
    out: list[str] = []
    if level.family != "stacking" or not isinstance(level.solution, StackingSolution):
        return [f"{level.id}: not a stacking level"]
    if level.box is None or tuple(sorted(level.box)) != tuple(sorted(config.box)):
        out.append(f"box {level.box} is not the config's {list(config.box)}")
        return out
    if level.difficulty != config.mode:
        out.append(f"difficulty {level.difficulty} is not the config's mode {config.mode}")
    shapes = [p.shape for p in level.pieces]
    placed = [level.solution.placements[p.name] for p in level.pieces]
    smallest = min(config.min_piece, config.fallback_min_piece or config.min_piece)
    rules = PieceRules(
        min_size=int(level.stats.get("min_piece", smallest)),
        max_size=config.max_piece_cells,
        planar=config.mode == "mid" and config.planar,
        distinct=config.mode == "hard",
    )
    if rules.min_size < smallest:
        out.append(f"min_piece {rules.min_size} is below the config's {smallest}")
    if not 2 <= len(shapes) <= config.max_pieces:
        out.append(f"{len(shapes)} pieces, the config allows 2..{config.max_pieces}")
    why = piece_problem(shapes, rules)
    if why is not None:
        out.append(why)
    if config.mode == "easy" and not all(
        s.is_cuboid() and _two_equal_sides(s.extent) for s in shapes
    ):
        out.append("easy pieces must be cuboids with two equal sides")
    if config.mode == "mid" and all(s.is_cuboid() for s in shapes):
        out.append("mid level of cuboids only")
    if config.mode == "hard" and all(is_planar(s) for s in shapes):
        out.append("hard level of flat pieces only")
    if has_isolated_piece(placed):
        out.append("isolated piece")
    if config.linear_assembly and assembly_order(placed, level.box) is None:
        out.append("no linear assembly")
    if level.optimal_steps != len(shapes):
        out.append(f"optimal_steps {level.optimal_steps} != {len(shapes)} pieces")
    try:
        nodes = packing.first_packing_nodes(shapes, level.box)
    except ValueError:
        out.append("the exact-cover engine finds no packing")
        return out
    if nodes < config.min_nodes:
        out.append(f"{nodes} exact-cover nodes, below the config's {config.min_nodes}")
    figures = level.stats.get("exact_cover", {})
    recorded = figures.get("nodes_first")
    if recorded is not None and recorded != nodes:
        out.append(f"stats record {recorded} nodes to the first packing, the engine takes {nodes}")
    if figures.get("solutions") is not None:
        budget = 2 * int(figures.get("count_budget") or 0) or None
        counted = packing.counted_packings(shapes, level.box, budget)
        if counted != (figures["solutions"], figures.get("distinct")):
            out.append(
                f"stats record {figures['solutions']} packings ({figures.get('distinct')} "
                f"distinct), the engine counts {counted}"
            )
    return out
