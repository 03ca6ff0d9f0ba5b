"""`python3 -m ricochet_dask`: see `ricochet_dask.client`."""

import sys

from ricochet_dask.client import main

sys.exit(main())
