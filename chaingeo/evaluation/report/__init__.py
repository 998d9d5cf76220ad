"""What a run becomes for people: the leaderboard tables and cost plot (:mod:`.tables`) and the
static HTML run viewer (:mod:`.site`, with its one stylesheet and script)."""
