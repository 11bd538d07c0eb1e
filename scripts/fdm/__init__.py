"""Python side of the project: write cases, run them with fdmRun, read their output.

    import sys; sys.path.insert(0, "<project>/scripts")
    from fdm import case, output
"""
import os

PROJECT_DIR = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
