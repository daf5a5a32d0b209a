"""What recon_eval writes: the versioned JSON document and the terminal table
(:mod:`.document`), the self-contained HTML report (:mod:`.html`) with its figures
(:mod:`.plots`, matplotlib), and the leaderboard's pages (:mod:`.leaderboard_page`)."""
