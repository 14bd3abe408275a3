import sys

from jaxcelt.cli import main

sys.exit(main())
