"""Figures. Physics never imports this package; it imports matplotlib lazily per module."""
