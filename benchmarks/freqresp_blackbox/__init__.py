"""Black-box check of ``synth freqresp`` against an independent numpy/scipy reference (see ``run.py``)."""
