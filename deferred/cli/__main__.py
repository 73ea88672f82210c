"""``python -m deferred.cli``: the ``deferred`` command."""

from deferred.cli.main import entry

if __name__ == "__main__":
    entry()
