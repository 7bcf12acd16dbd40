"""Nonlinear sampled simulation: blocks, closed and open loop, step metrics, limit cycles."""
