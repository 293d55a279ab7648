//! kerf trajectory executor node
