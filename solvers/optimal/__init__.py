"""The optimal plan length o_i: A* with pattern databases, and proven bounds for towers of burr
units (the block bound for moves of one piece, the class bound and its search for several)."""
