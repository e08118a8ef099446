"""The SPD solvers behind one interface: the backends of the active set methods.

Nothing is imported here (the modules import each other and the core below them); the public
names are re-exported by :mod:`signorini.algebra`.

====================  ==========================================================================
``solvers``           the SPD solver interface (analysis once per pattern), ``solver_usage``
``requests``          the solver factory protocol and its request
``beside``            one background thread for MKL's calls that release the interpreter
``superlu``           SuperLU backend (always available): SPD, LU for non-symmetric; factory
``mkl``               how MKL's runtime library is found and loaded
``pardiso``           MKL PARDISO through ctypes (SPD), its factory; METIS
``pardiso_lu``        PARDISO's LU for non-symmetric matrices
``petsc_import``      how petsc4py is found and imported (``petsc_module``, ``petsc_library``)
``petsc_rows``        the base of the PETSc backends: a matrix's rows over the ranks
``petsc``             PETSc + MUMPS (``"petsc"``)
``petsc_gamg``        CG + GAMG through PETSc, the rigid-body near-nullspace (``"petsc-gamg"``)
``selection``         the backends by name (``SOLVERS``, ``"auto"``), ``make_solver``
====================  ==========================================================================
"""
