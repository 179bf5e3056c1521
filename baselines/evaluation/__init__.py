"""The scoring harness: seeded, scored episodes (:mod:`.episodes`) and the scorecards of
policies on envs (:mod:`.harness`)."""
