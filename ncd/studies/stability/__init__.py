"""§2 claim: Contact Dynamics against a soft-contact MD baseline on stiff and extreme cases."""
