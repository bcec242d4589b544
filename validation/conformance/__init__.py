"""specref as an oracle for other renderers: canonical scenes, references, export and the check.

- :mod:`validation.conformance.scenes`: the registry of conformance scenes (what each tests and
  the mistakes it catches) and the scene files shipped in ``data:conformance/``;
- :mod:`validation.conformance.references`: each scene's reference, rendered by specref's oracle
  path with a per-pixel standard error, written as XYZ and spectral EXRs with a manifest of
  SHA-256 digests;
- :mod:`validation.conformance.check`: a renderer's images against the references, pass or fail
  per scene, and the diagnosis of the usual mistakes (:mod:`validation.conformance.diagnose`);
- :mod:`validation.conformance.export`: the scenes in specref's and Mitsuba 3's formats.

docs/conformance.md describes the suite; ``specref conformance list|references|export|check``
runs it.
"""
