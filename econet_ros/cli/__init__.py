"""The ``econet`` command line (see main.py); ``econet_ros.cli:main`` is the console script."""
from .main import main

__all__ = ["main"]
