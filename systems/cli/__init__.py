"""The `attitude` command line: its parser, its commands and their plots."""
