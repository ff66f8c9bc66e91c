"""Analyses over the checked model (incompatibility groups, rule compilation, ...)."""
