import sys

from recon_eval.cli import main

sys.exit(main())
