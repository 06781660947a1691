import sys

from tailbeam.cli import main

sys.exit(main())
