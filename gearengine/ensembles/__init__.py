"""Ensembles: questions whose answer is many runs of one design (coexisting attractors,
manufacturing tolerances, remedies), each built from envelope checks or lanes of the lock-step
kernels and returned with the runs that decide it. ``remedies`` searches the design levers
(damping, transmission error, backlash, stiffness variation, torque ripple) for the smallest
change that makes an operating envelope pass, with a Melnikov guarantee and a verified
numerical bound per lever.
"""
