"""Fault-injection campaigns (seed 004 ch. 4): mutants of a planning model run on every
configuration x mission x world x run, each experiment in a process with a hard timeout, the
results in a SQLite store as they finish (an interrupted campaign resumes), locally or on Dask
distributed, and the seed's measures averaged over sets of activities.

    specc campaign examples/tug --mutants 40 --runs 3 --configs Robot1,Robot1/2

`experiments` runs one experiment, `store` keeps the results, `engines` runs many (local pool,
Dask), `campaign` orders them and applies the seed's filters, `report` writes the tables and the
bar charts of Fig 4.14."""
