"""Subcommands of the ``mutext`` command line besides the demos (each: ``add_arguments``, ``run``)."""
