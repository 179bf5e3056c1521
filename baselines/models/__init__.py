"""Learned-model files: the network classes a model file may name, safe loading of SB3 zips,
VecNormalize statistics as JSON."""
