"""Gates: the rules that pass or fail a design, and the search for what makes it pass.

``envelope`` (the operating envelope's rules, failing windows, JUnit), ``runup`` (``check
--runup``) and ``remedies`` (the job that searches the design levers for the smallest change
that makes a failing envelope pass under these rules).
"""
