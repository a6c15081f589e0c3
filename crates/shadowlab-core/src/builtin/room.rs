pub fn build() -> crate::scene::Scene { super::planebox::build() }
