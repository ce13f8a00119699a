"""Command line: ``impactsym <command> ...``, one module per command group
(``scene_commands``: solve, invert, reconstruct, crash3, compare; ``sweeps``:
sweep, sample; ``tools``: validate, compile), ``common`` what they share and
``main`` the table, the parser and the exit codes.

Commands are registered in :data:`COMMANDS` as ``name -> Command``: its
``add_arguments`` fills the command's sub-parser, its ``run`` takes the parsed
arguments and returns the exit code.  Any bad input (a scene error, an
unreadable file, a wrong argument) prints one line ``impactsym: error:
<reason>`` on stderr and exits with code 2.
"""

from .common import Command
from .main import COMMANDS, build_parser, main, run

__all__ = ["COMMANDS", "Command", "build_parser", "main", "run"]
