"""``nmpc_learned_id``: the oracle's NMPC fed by a learned estimate of the plant (RMA's
adaptation module, Kumar et al. 2021): the features it reads, the labels it learns, the
network, the controller and its training."""
