"""``python -m riskrf.cli``: the ``riskrf`` command (:func:`riskrf.cli.command`)."""
import sys

from . import command

if __name__ == "__main__":
    sys.exit(command())
