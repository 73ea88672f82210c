"""``python -m deferred``: the ``deferred`` command."""

from deferred.cli import entry

if __name__ == "__main__":
    entry()
