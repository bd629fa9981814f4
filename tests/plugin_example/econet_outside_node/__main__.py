import sys

from econet_outside_node import main

sys.exit(main())
