"""``python -m steerlab`` = the ``steerlab`` command."""

from steerlab.cli import console_main

console_main()
