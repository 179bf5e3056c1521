"""What the layers above share: the env model, observation fields, sub-envs, atomic files,
checked values, env kwargs and package data."""
