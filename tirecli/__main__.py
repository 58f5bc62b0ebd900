"""``python -m tirecli``: the same as the ``tirecli`` command."""
from tirecli.cli.main import main

if __name__ == "__main__":
    main()
