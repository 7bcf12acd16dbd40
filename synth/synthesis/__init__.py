"""Optimization-based synthesis of fixed-structure controllers (convex-concave with cvxpy, NLP with casadi)."""

__all__ = []
