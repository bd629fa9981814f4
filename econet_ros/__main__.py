"""``python -m econet_ros`` runs the ``econet`` command line."""
import sys

from .cli import main

sys.exit(main())
