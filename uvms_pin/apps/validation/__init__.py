"""Validation against measurements: the Hinsdale 2023 pool trials (``uvms-pin validate pool``)."""
