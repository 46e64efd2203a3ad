"""Layer 1, core: the model types and their validation.

Errors, argument primitives (:mod:`.validate`), the numba cache (:mod:`.jit`), the
:class:`~ncd.core.model.Scene` and its checks, contact detection, :class:`~ncd.core.contacts.Contacts`
and :func:`~ncd.core.scene.make_scene`. Imports nothing else of ncd.
"""
