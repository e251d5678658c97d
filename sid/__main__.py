"""``python -m sid``: the ``sid`` command line."""

from sid.cli import main

raise SystemExit(main())
