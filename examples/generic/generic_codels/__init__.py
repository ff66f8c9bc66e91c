"""Codels of the generic two-module system of seed 000 §3.8 (Fig 3.9).

The thesis gives the functions' conflicts only; the codels are placeholders that run a fixed
number of periods. Same interface as ``hilare_codels``: ``sdi`` carries the ``internal_data``
fields, ``request`` the inputs; a codel returns "exec", "end", "ether" or a fail message.
"""
