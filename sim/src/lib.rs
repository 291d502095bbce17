//! The world: ECS components, built-in scenes, scenario files, glTF import, animation systems.
