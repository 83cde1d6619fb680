"""The verifier's one exception type (trusted)."""


class CertificateError(ValueError):
    """A certificate that is malformed or whose claims do not check."""
