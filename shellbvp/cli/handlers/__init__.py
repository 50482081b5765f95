"""The subcommands' handlers: ``handlers/NAME.py`` holds ``run(args)`` of ``shellbvp NAME``.

Each subcommand's parser (``shellbvp/cli/NAME.py``: ``add_parser``) imports its handler when the
command is dispatched, so that building the parser loads no numpy (tests/test_imports.py); a
handler imports the package at its top.  This package imports none of them.
"""
