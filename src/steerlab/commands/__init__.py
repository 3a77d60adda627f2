"""CLI subcommands beyond the core ones in :mod:`steerlab.cli`, discovered by module.

Each module here defines ``register(sub, formatter_class)`` that adds one or more parsers to
the ``argparse`` sub-parser action ``sub`` and sets ``func`` (``func(args) -> exit code``) with
``set_defaults``. Raise :class:`steerlab.errors.InputError` for bad input (exit 2, one line).
Use :func:`steerlab.cli.staged_output` for ``--out`` directories and
:func:`steerlab.cli.dump_json` for JSON. Import heavy modules inside ``func``, not at the top,
so that ``steerlab --help`` stays fast.
"""



def command_modules():
    """The command modules, in name order."""
    from steerlab.plugins import package_modules

    return package_modules("steerlab.commands")
