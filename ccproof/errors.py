"""Exception types shared by every layer (imports nothing from ccproof).

A malformed certificate is reported by the trusted verifier's own
:class:`ccproof.certify.verify.errors.CertificateError` (a ``ValueError``): the verifier imports
nothing of the package outside the trusted base (docs/trusted_base.md), so that one exception type
is deliberately not a :class:`CCProofError` and has no twin here.
"""


class CCProofError(ValueError):
    """Base class of the errors ccproof raises for bad input (a ``ValueError``).

    Catch it to handle every input error of the package (docs/api.md, "Errors").

    Parameters
    ----------
    message : str
        What is wrong, naming the offending input (face, edge, vertex, field or valence).

    Examples
    --------

    >>> issubclass(MeshError, CCProofError), issubclass(CCProofError, ValueError)
    (True, True)
    >>> import ccproof
    >>> try:
    ...     ccproof.inverse_characteristic_map(5, [-1.0], [0.0])
    ... except ValueError as exc:
    ...     print(type(exc).__name__, str(exc)[:45])
    CCProofError image first coordinate is negative at index 0
    """


class ValenceError(CCProofError):
    """A valence that is not an integer >= 3.

    Parameters
    ----------
    message : str
        What is wrong, naming the offending value.

    Examples
    --------

    >>> check_valence(2.5)
    Traceback (most recent call last):
    ...
    ccproof.errors.ValenceError: valence must be an integer >= 3, got 2.5
    """


class TableNotFoundError(CCProofError):
    """A certified table that does not exist; the message lists the ones that do.

    Parameters
    ----------
    message : str
        What is wrong, naming the offending valence and listing the tables that exist.

    Examples
    --------

    >>> from ccproof.tables.numeric import load_table
    >>> load_table(200)
    Traceback (most recent call last):
    ...
    ccproof.errors.TableNotFoundError: no certified table for valence 200; tables exist for k = 3..100; k >=40
    """


class MeshError(CCProofError):
    """A mesh that is not a valid manifold quad mesh; the message names the element.

    Parameters
    ----------
    message : str
        What is wrong, naming the offending face, edge or vertex.

    Examples
    --------

    >>> from ccproof.mesh import QuadMesh
    >>> QuadMesh([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 7]])
    Traceback (most recent call last):
    ...
    ccproof.errors.MeshError: ...
    """


def check_valence(k: object, *, minimum: int = 3) -> int:
    """Return ``k`` as a Python ``int`` after checking it is an integer valence >= ``minimum``.

    Parameters
    ----------
    k : object
        The valence: an ``int``, a NumPy integer, an integral float (``5.0``) or a decimal string (``"5"``).
        ``bool`` is refused.
    minimum : int, optional
        Smallest accepted valence (default 3, the smallest valence of a Catmull-Clark vertex).

    Returns
    -------
    int
        ``k`` as a Python integer.

    Raises
    ------
    ValenceError
        If ``k`` is not an integer or is below ``minimum``; the message quotes ``k``.

    Examples
    --------

    >>> check_valence(5)
    5
    >>> check_valence(2)
    Traceback (most recent call last):
    ...
    ccproof.errors.ValenceError: valence must be an integer >= 3, got 2
    """
    if isinstance(k, bool):
        raise ValenceError(f"valence must be an integer >= {minimum}, got {k!r}")
    try:
        import numbers

        if isinstance(k, numbers.Integral):
            kk = int(k)
        elif isinstance(k, numbers.Real) and k == k and float(k).is_integer():
            kk = int(float(k))
        elif isinstance(k, str) and k.strip().lstrip("+").isdigit():
            kk = int(k)
        else:
            raise TypeError
    except (TypeError, ValueError, OverflowError):
        raise ValenceError(f"valence must be an integer >= {minimum}, got {k!r}") from None
    if kk < minimum:
        raise ValenceError(f"valence must be an integer >= {minimum}, got {k!r}")
    return kk
