//! modelDescription.xml from a scene, and packaging the `.fmu` archive.
