"""Synthesis: new motion made from captured motion (blends, transitions, generated paths)."""
