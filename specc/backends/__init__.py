"""Back ends: model (+ analyses) -> files of the generated robot package."""
