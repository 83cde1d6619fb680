"""The verifier's one exception type (trusted)."""


class CertificateError(ValueError):
    """A malformed certificate or a claim that does not check; the verifier turns it into FAILED with the reason.

    >>> from ccproof.certify.verify import verify_certificate
    >>> verify_certificate({"schema": "ccproof.c1/2", "valence": 2}, log=lambda line: None).error
    'valence 2 outside 3..10^6'
    """
