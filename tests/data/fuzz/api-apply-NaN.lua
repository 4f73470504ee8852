-- fuzz case: dm.apply(0/0): unknown function '-nan'
-- fixed in the hardening work (a regression fails the replay)
return function(P, H, F)
return F["dm.apply"](H["nan"])
end
