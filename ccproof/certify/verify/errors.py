"""The verifier's one exception type (trusted)."""


class CertificateError(ValueError):
    """A certificate that is malformed or whose claims do not check (the verifier turns it into FAILED).

    Parameters
    ----------
    message : str
        The reason, naming the field or part.

    Examples
    --------
    >>> from ccproof.certify.verify import verify_certificate
    >>> verify_certificate({"schema": "ccproof.c1/2", "valence": 2}, log=lambda line: None).error
    'valence 2 outside 3..10^6'
    """
