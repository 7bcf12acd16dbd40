"""Reports for people: HTML pages, figures and the JSON they are rendered from."""

__all__ = []
