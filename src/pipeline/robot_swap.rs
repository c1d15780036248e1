//! A new robot, new parameters or a new SRDF for the pipeline: built from the robot's source
//! (files or a `robot_description`), the latest SRDF applied where it fits, and swapped in whole
//! with the planning scene's objects; on error everything stays as it was.

use super::state_pipeline::{Pipeline, RobotSource};
use crate::checker::{Checker, CheckerError};
use crate::model::Params;

impl Pipeline {
    /// A new robot from URDF text (a `robot_description` message), swapped in whole; on error the
    /// current robot stays. Merged joint positions are dropped when the new robot's joints differ.
    pub fn set_robot_description(&mut self, urdf: &str, source: &str) -> Result<(), CheckerError> {
        let params = self.params().clone();
        let mut params = params;
        if self.semantic_deferred {
            // Applied below from the text read at start, where a misfit refuses the robot.
            params.robot_semantic_file.clear();
        }
        let mut checker = crate::limits::contain_panic(|| Checker::from_description(params, urdf, source)).map_err(CheckerError::Panicked)??;
        if self.semantic_deferred {
            if let Some((text, file)) = &self.semantic {
                crate::limits::contain_panic(|| checker.apply_semantic(text, file))
                    .map_err(CheckerError::Panicked)?
                    .map_err(|e| CheckerError::Srdf(format!("robot_semantic_file {file} does not fit this robot: {e}")))?;
                checker.set_semantic_file_name(file.clone());
            }
        } else {
            self.apply_latest_semantic(&mut checker);
        }
        self.source = RobotSource::Description { urdf: urdf.into(), source: source.to_owned() };
        self.replace(checker);
        Ok(())
    }

    /// New parameters: the checker is rebuilt with the robot from the same source (a robot
    /// received as a description stays); on error everything stays as it was. The input files
    /// the pipeline started with stay: they are not parameters.
    pub fn set_params(&mut self, mut params: Params) -> Result<(), CheckerError> {
        params.input_files = self.params().input_files.clone();
        let was_deferred = self.semantic_deferred;
        // A different SRDF file is a new choice, checked against the robot in force.
        if self.semantic.as_ref().is_none_or(|(_, file)| *file != params.robot_semantic_file) {
            self.semantic_deferred = false;
        }
        match self.rebuild(params) {
            Ok(checker) => {
                self.replace(checker);
                Ok(())
            }
            Err(e) => {
                self.semantic_deferred = was_deferred;
                Err(e)
            }
        }
    }

    /// A new SRDF (a `robot_description_semantic` message), swapped in whole: its
    /// `disable_collisions` become the allowed collision matrix and its groups serve
    /// `check_state_validity`. One naming a link or joint the robot lacks is refused and the
    /// current matrix stays; it is tried again on every robot that arrives later.
    pub fn set_robot_semantic(&mut self, text: &str, source: &str) -> Result<(), CheckerError> {
        // Kept even when it does not fit this robot: the robot it belongs to may come next.
        self.semantic = Some((text.into(), source.to_owned()));
        self.semantic_deferred = false;
        let checker = crate::limits::contain_panic(|| self.checker.with_other_semantic(text, source)).map_err(CheckerError::Panicked)??;
        // A new SRDF is the matrix from now on, in place of one a planning scene gave.
        self.scene.matrix = None;
        self.replace(checker);
        Ok(())
    }

    /// The checker for `params` with the robot from the current source, and the latest SRDF
    /// received when it fits (else the parameters' file or the default pairs, with a warning).
    fn rebuild(&mut self, params: Params) -> Result<Checker, CheckerError> {
        let mut checker = self.build_from_source(params)?;
        if !self.semantic_deferred {
            self.apply_latest_semantic(&mut checker);
        }
        Ok(checker)
    }

    fn build_from_source(&self, mut params: Params) -> Result<Checker, CheckerError> {
        let deferred = self.semantic_deferred.then(|| std::mem::take(&mut params.robot_semantic_file));
        let mut checker = self.build_checker(params)?;
        if let Some(file) = deferred {
            if let (RobotSource::Description { .. }, Some((text, _))) = (&self.source, &self.semantic) {
                checker.apply_semantic(text, &file).map_err(|e| CheckerError::Srdf(format!("robot_semantic_file {file} does not fit this robot: {e}")))?;
            }
            checker.set_semantic_file_name(file);
        }
        Ok(checker)
    }

    fn build_checker(&self, params: Params) -> Result<Checker, CheckerError> {
        crate::limits::contain_panic(|| match &self.source {
            RobotSource::Files => Checker::from_params(params),
            RobotSource::Description { urdf, source } => Checker::from_description(params, urdf, source),
        })
        .map_err(CheckerError::Panicked)?
    }

    fn apply_latest_semantic(&mut self, checker: &mut Checker) {
        if let Some((text, source)) = &self.semantic {
            match crate::limits::contain_panic(|| checker.apply_semantic(text, source)) {
                Ok(Ok(())) => {}
                Ok(Err(e)) => self.warnings.push(format!("the SRDF from {source} does not fit this robot ({e}); its self-collision pairs are not used")),
                Err(e) => self.warnings.push(format!("the SRDF from {source} could not be applied: {e}")),
            }
        }
    }
}
