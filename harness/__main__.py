"""``python -m harness`` is the ``sidbench`` command."""
from harness.cli import main

raise SystemExit(main())
