"""``python -m stickslip.cli``: the ``stickslip`` command."""

from stickslip.cli import main

raise SystemExit(main())
