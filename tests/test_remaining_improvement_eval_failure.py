"""A trial point casadi cannot evaluate is skipped, not raised (session 62: ``synth.ident.identify`` ended in a
``RuntimeError`` traceback, "Evaluation failed" of the model at a Gauss-Newton trial of a fit stopped at its limit,
on a random train of ``benchmarks/ident_delay_alias.py``, seed 1, case 16, on the code of every earlier session)."""

import numpy as np

from synth.ident.fit_failure import remaining_improvement


class FailingBeyond:
    """``y = a t`` with the decision variable ``2 a``; the model cannot be evaluated beyond ``a = 1.5``."""

    p, scale = 1, np.array([0.5])

    def yhat_fn(self, xs, par):
        if xs[0] * 0.5 > 1.5:
            raise RuntimeError("Error in Function::call for 'yhat' [MXFunction]: Evaluation failed")
        return xs[0] * 0.5 * par


def test_a_trial_that_cannot_be_evaluated_is_skipped_and_the_shorter_steps_still_count():
    t = np.arange(5.0)
    J, resid = t[:, None], 2.0 * t  # stopped at a = 0 where a = 2 fits: the full step (a = 2) fails to evaluate
    left = remaining_improvement(FailingBeyond(), np.array([0.0]), t, J, resid, J.T @ J, np.array([0.5]), 1.0, None,
                                 2.0 * t, None, False, 0.1)
    # the half step, a = 1, is the best that evaluates: SSR 120 -> 30, sqrt(90)
    assert left == np.sqrt(90.0)
