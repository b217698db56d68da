import sys

from winder.cli import main

sys.exit(main())
