//! The kinematic tree of a URDF: links joined by joints, checked to be a tree with one root.

use std::collections::HashMap;

use crate::error::UrdfError;
use crate::parse::Robot;

/// Index of links and joints, with each link's parent joint and child joints (file order).
#[derive(Debug)]
pub struct Tree {
    pub link_index: HashMap<String, usize>,
    /// Per link: the joint whose child it is (`None` for the root).
    pub parent_joint: Vec<Option<usize>>,
    /// Per link: the joints whose parent it is, in file order.
    pub child_joints: Vec<Vec<usize>>,
    /// Per joint: parent and child link indices.
    pub ends: Vec<(usize, usize)>,
    pub root: usize,
}

impl Tree {
    /// Checks names, references, the single root and the absence of cycles and closed loops.
    pub fn build(robot: &Robot) -> Result<Tree, UrdfError> {
        let mut link_index = HashMap::new();
        for (i, link) in robot.links.iter().enumerate() {
            if link_index.insert(link.name.clone(), i).is_some() {
                return Err(UrdfError::invalid(
                    format!("link `{}`", link.name),
                    "defined twice",
                ));
            }
        }
        let mut joint_names = HashMap::new();
        let mut parent_joint: Vec<Option<usize>> = vec![None; robot.links.len()];
        let mut child_joints = vec![Vec::new(); robot.links.len()];
        let mut ends = Vec::with_capacity(robot.joints.len());
        for (j, joint) in robot.joints.iter().enumerate() {
            let element = format!("joint `{}`", joint.name);
            if joint_names.insert(joint.name.as_str(), j).is_some() {
                return Err(UrdfError::invalid(element, "defined twice"));
            }
            let find = |role: &str, name: &str| {
                link_index.get(name).copied().ok_or_else(|| {
                    UrdfError::invalid(
                        format!("{element}.{role}"),
                        format!("{role} link `{name}` does not exist"),
                    )
                })
            };
            let parent = find("parent", &joint.parent)?;
            let child = find("child", &joint.child)?;
            if parent == child {
                return Err(UrdfError::invalid(
                    element,
                    format!("joins link `{}` to itself (a cycle)", joint.parent),
                ));
            }
            if let Some(other) = parent_joint[child] {
                return Err(UrdfError::invalid(
                    element,
                    format!(
                        "link `{}` is already the child of joint `{}`: closed loops are not supported",
                        joint.child, robot.joints[other].name
                    ),
                ));
            }
            parent_joint[child] = Some(j);
            child_joints[parent].push(j);
            ends.push((parent, child));
        }
        let roots: Vec<usize> = (0..robot.links.len())
            .filter(|&l| parent_joint[l].is_none())
            .collect();
        let root = match roots.as_slice() {
            [root] => *root,
            [] => {
                return Err(UrdfError::invalid(
                    format!("joint `{}`", robot.joints[0].name),
                    "every link has a parent joint: the joints form a cycle",
                ));
            }
            [a, b, ..] => {
                return Err(UrdfError::invalid(
                    format!("link `{}`", robot.links[*b].name),
                    format!(
                        "two root links, `{}` and `{}`: every link but one must be the child of a joint",
                        robot.links[*a].name, robot.links[*b].name
                    ),
                ));
            }
        };
        let tree = Tree {
            link_index,
            parent_joint,
            child_joints,
            ends,
            root,
        };
        // One root and one parent per link: a link not reached from the root lies on a cycle.
        let reached = tree.subtree(root);
        if let Some(l) = (0..robot.links.len()).find(|l| !reached.contains(l)) {
            let j = tree.parent_joint[l].expect("only the root lacks a parent");
            return Err(UrdfError::invalid(
                format!("joint `{}`", robot.joints[j].name),
                format!(
                    "link `{}` is not connected to the root `{}`: the joints form a cycle",
                    robot.links[l].name, robot.links[root].name
                ),
            ));
        }
        Ok(tree)
    }

    /// Links of the subtree rooted at `link`, depth first, children in file order.
    pub fn subtree(&self, link: usize) -> Vec<usize> {
        let mut order = Vec::new();
        let mut stack = vec![link];
        while let Some(l) = stack.pop() {
            order.push(l);
            for &j in self.child_joints[l].iter().rev() {
                stack.push(self.ends[j].1);
            }
        }
        order
    }

    /// The joints from `from` down to its descendant `to`, or `None` if `to` is not below it.
    pub fn path(&self, from: usize, to: usize) -> Option<Vec<usize>> {
        let mut joints = Vec::new();
        let mut link = to;
        while link != from {
            let j = self.parent_joint[link]?;
            joints.push(j);
            link = self.ends[j].0;
        }
        joints.reverse();
        Some(joints)
    }
}
