"""The shipped models: their manifest and held-out results (:mod:`.manifest`), their cards
(:mod:`.cards`)."""
