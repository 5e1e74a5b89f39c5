//! Where a scene's inputs come from: objects (`synth:cloth`, `synth:cloth-obstacle` or a file),
//! BTF materials (`synth:woven` or a `.btfpca`) and the environment (`synth:sky` or a map),
//! resolved against the scene file's folder.

use std::path::PathBuf;

use super::{SYNTH_PREFIX, Scene};
use crate::Error;

/// Where an object's geometry comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum GeometrySource {
    /// The synthetic cloth drape (`synth:cloth`).
    SynthCloth,
    /// The obstacle the synthetic cloth falls on (`synth:cloth-obstacle`).
    SynthClothObstacle,
    /// A mesh or animation file or folder.
    File(PathBuf),
}

/// Where the BTF material comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BtfSource {
    /// The woven-cloth BTF of `synth`, generated and compressed in memory.
    SynthWoven,
    /// A `.btfpca` file.
    File(PathBuf),
}

/// Where the environment comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum EnvironmentSource {
    /// The procedural sky (`synth:sky`).
    SynthSky,
    /// An equirectangular map file.
    File(PathBuf),
}

impl Scene {
    /// Resolve an object's source.
    ///
    /// # Errors
    /// [`Error::Scene`] for an unknown `synth:` name.
    pub fn geometry_source(&self, index: usize) -> Result<GeometrySource, Error> {
        let object = &self.objects[index];
        match object.source.strip_prefix(SYNTH_PREFIX) {
            Some("cloth") => Ok(GeometrySource::SynthCloth),
            Some("cloth-obstacle") => Ok(GeometrySource::SynthClothObstacle),
            Some(other) => Err(self.invalid(
                &format!("object[{index}] ({}).source", object.name),
                format!("unknown procedural source \"synth:{other}\"; known: synth:cloth, synth:cloth-obstacle"),
            )),
            None => Ok(GeometrySource::File(self.base_dir.join(&object.source))),
        }
    }

    /// The `topology` mesh of object `index`, resolved against the scene's folder.
    pub fn topology_path(&self, index: usize) -> Option<PathBuf> {
        self.objects[index]
            .topology
            .as_ref()
            .map(|t| self.base_dir.join(t))
    }

    /// Resolve the BTF material's source.
    ///
    /// # Errors
    /// [`Error::Scene`] for an unknown `synth:` name.
    pub fn btf_source(&self) -> Result<BtfSource, Error> {
        self.material_source("btf.source", &self.btf.source)
    }

    /// Resolve a BTF named in the scene under `key` (`btf.source`, `btf.parts.NAME`).
    ///
    /// # Errors
    /// [`Error::Scene`] naming `key` for an unknown `synth:` name.
    pub fn material_source(&self, key: &str, source: &str) -> Result<BtfSource, Error> {
        match source.strip_prefix(SYNTH_PREFIX) {
            Some("woven") => Ok(BtfSource::SynthWoven),
            Some(other) => Err(self.invalid(
                key,
                format!("unknown procedural source \"synth:{other}\"; known: synth:woven"),
            )),
            None => Ok(BtfSource::File(self.base_dir.join(source))),
        }
    }

    /// Resolve the environment's source, if there is an environment.
    ///
    /// # Errors
    /// [`Error::Scene`] for an unknown `synth:` name.
    pub fn environment_source(&self) -> Result<Option<EnvironmentSource>, Error> {
        let Some(env) = &self.environment else {
            return Ok(None);
        };
        match env.source.strip_prefix(SYNTH_PREFIX) {
            Some("sky") => Ok(Some(EnvironmentSource::SynthSky)),
            Some(other) => Err(self.invalid(
                "environment.source",
                format!("unknown procedural source \"synth:{other}\"; known: synth:sky"),
            )),
            None => Ok(Some(EnvironmentSource::File(
                self.base_dir.join(&env.source),
            ))),
        }
    }
}
