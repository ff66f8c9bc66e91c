"""Fault injection into planning domains by mutation of the model (seed 004 §4.1.3).

The seed's SESAME tool substituted strings in Modele1's text and threw away the mutants that did
not compile. Here the frozen model of the `domain` block is mutated node by node (five classes:
numeric, variable, value, operator, deletion; see `specc.mutation.edits`), each mutant is printed
back as spec text, and the text goes through the same parse and checks as `specc check`.

    from specc.mutation import enumerate_mutants, keep_valid, mutant_domain
    mutants = enumerate_mutants(Path("examples/tug"), domain="warehouse")
    kept = keep_valid(mutants)                # counts per class: kept.counts()
    chosen = kept.sample(28, seed=1)          # stratified by class
    Planner(mutant_domain(chosen[0])).plan(problem)
"""

from __future__ import annotations

from specc.mutation.edits import CLASSES, Edit, MutationClass
from specc.mutation.mutants import (
    ClassCounts,
    Mutant,
    MutantSet,
    MutationError,
    MutationTarget,
    Rejection,
    default_workers,
    draw_kept,
    enumerate_mutants,
    find_mutant,
    keep_valid,
    mutant_domain,
    mutation_target,
)

__all__ = [
    "CLASSES", "ClassCounts", "Edit", "Mutant", "MutantSet", "MutationClass", "MutationError", "MutationTarget",
    "Rejection", "default_workers", "draw_kept", "enumerate_mutants", "find_mutant", "keep_valid", "mutant_domain",
    "mutation_target",
]
