"""``python -m robocfg`` = the ``robocfg`` command."""

from robocfg.cli.app import main

main()
