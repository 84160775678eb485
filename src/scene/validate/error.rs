//! A scene that cannot be run, and the builder whose checks report one at a key.

/// A scene that cannot be run, with where and why.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone, PartialEq)]
pub struct SceneError {
    pub file: String,
    pub key: String,
    pub message: String,
}

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.key.is_empty() {
            write!(f, "{}: {}", self.file, self.message)
        } else {
            write!(f, "{}: {}: {}", self.file, self.key, self.message)
        }
    }
}

impl std::error::Error for SceneError {}

/// Validates a scene file's contents into a `Problem`; its checks are spread over
/// validate.rs and the files beside this one.
pub(super) struct Builder {
    pub(super) file: String,
}

impl Builder {
    pub(super) fn err(&self, key: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError {
            file: self.file.clone(),
            key: key.into(),
            message: message.into(),
        }
    }
}
