"""The model: parameters of the block (eq. 1) and the chain (eq. 4), and closed-form steady states."""
