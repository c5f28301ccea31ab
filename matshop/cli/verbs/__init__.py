"""One module per ``matshop`` verb (listed in :mod:`matshop.cli.registry`)."""
